//! The detected small objects: the map's small-object cells (§V, a-1)
//! grouped into objects, each with its centre of mass (§V step a-2, as the
//! paper evaluates Fig. 8: "the average error of detected CoM positions").

use nalgebra::Vector2;
use rustc_hash::FxHashSet;

use crate::grid::NdtGrid;
use crate::key::CellKey;

/// One detected small (sub-grid scale) object.
#[derive(Debug, Clone, PartialEq)]
pub struct SmallObject {
    /// Centre of mass of the object's points, map frame \[m\]: `Σm / ΣM` over
    /// its cells (eq. 6 sums).
    pub center: Vector2<f64>,
    /// Its cells, sorted by key.
    pub cells: Vec<CellKey>,
    /// Total number of points `ΣM` in its cells.
    pub points: u64,
}

/// Groups the cells `keys` of `grid` into objects: cells that touch (8-
/// neighbourhood) belong to the same object. Keys without a cell in the grid
/// are ignored. Objects are sorted by their smallest cell key.
pub fn group_objects(grid: &NdtGrid, keys: &[CellKey]) -> Vec<SmallObject> {
    let cell_size = grid.cell_size();
    let members: FxHashSet<CellKey> = keys
        .iter()
        .copied()
        .filter(|k| grid.stats(*k).is_some())
        .collect();
    let mut sorted: Vec<CellKey> = members.iter().copied().collect();
    sorted.sort_unstable();
    let mut done: FxHashSet<CellKey> = FxHashSet::default();
    let mut out = Vec::new();
    for seed in sorted {
        if !done.insert(seed) {
            continue;
        }
        let mut cells = vec![seed];
        let mut next = 0;
        while next < cells.len() {
            let k = cells[next];
            next += 1;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let n = k.offset(dx, dy);
                    if members.contains(&n) && done.insert(n) {
                        cells.push(n);
                    }
                }
            }
        }
        cells.sort_unstable();
        let (mut sum, mut points) = (Vector2::zeros(), 0u64);
        for k in &cells {
            if let Some(s) = grid.stats(*k) {
                sum += s.sum + k.center(cell_size) * s.points();
                points += s.count;
            }
        }
        if points > 0 {
            out.push(SmallObject {
                center: sum / points as f64,
                cells,
                points,
            });
        }
    }
    out
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::Pose2;

    #[test]
    fn touching_cells_form_one_object_with_the_points_centre() {
        let mut grid = NdtGrid::new(0.02).unwrap();
        let pts = [[0.011, 0.011], [0.031, 0.011], [0.029, 0.031], [0.5, 0.5]];
        let keys = grid.insert(&pts, Pose2::identity()).unwrap();
        let objects = group_objects(&grid, &keys);
        assert_eq!(objects.len(), 2);
        assert_eq!(objects[0].cells.len(), 3);
        assert_eq!(objects[0].points, 3);
        let c = objects[0].center;
        assert!((c - Vector2::new(0.071 / 3.0, 0.053 / 3.0)).norm() < 1e-12);
        assert_eq!(objects[1].points, 1);
        assert!((objects[1].center - Vector2::new(0.5, 0.5)).norm() < 1e-12);
    }
}
