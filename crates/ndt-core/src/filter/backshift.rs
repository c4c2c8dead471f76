//! §V-B(2) "Small object in front of wall", step b-2: beyond the reliable
//! range a thin object in front of a wall is measured shifted backward (by
//! 5 cm in the paper's Fig. 7b). So a new point of a small cluster in Area 2
//! is not stored when the map already holds a cell short of it along its
//! beam, within a window: the point is likely the backward-shifted image of
//! that cell's object.

use nalgebra::Vector2;

use crate::filter::walkmap::WalkMap;
use crate::key::CellKey;

/// §V step b-2: `true` when `map` holds a cell that the beam from `sensor`
/// to `hit` (map frame \[m\]) crosses within `window` \[m\] short of the hit,
/// other than the hit's own cell: "there are former grid data in the short
/// of radiation direction".
pub fn former_cell_short_of(
    map: &mut WalkMap<'_>,
    sensor: Vector2<f64>,
    hit: Vector2<f64>,
    window: f64,
) -> bool {
    let cell_size = map.grid().cell_size();
    let Some(hit_key) = CellKey::of(hit, 1.0 / cell_size) else {
        return false;
    };
    let ray = hit - sensor;
    let range = ray.norm();
    if range == 0.0 || window <= 0.0 {
        return false;
    }
    let start = if window >= range {
        sensor
    } else {
        hit - ray * (window / range)
    };
    let mut found = false;
    // The walk crosses the blocks the occupancy shows empty without visiting
    // them.
    map.walk(start, hit, |key, occupied| {
        if key != hit_key && occupied {
            found = true;
        }
        !found
    });
    found
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::{NdtGrid, Pose2};

    #[test]
    fn b2_flags_points_just_behind_a_known_cell() {
        let mut grid = NdtGrid::new(0.02).unwrap();
        // A known stick surface at (1.0, 0.0).
        grid.insert(&[[1.0, 0.001]], Pose2::identity()).unwrap();
        let sensor = Vector2::zeros();
        // One map read by every beam, as a scan's beams read it.
        let mut map = WalkMap::new(&grid);
        // The same stick measured 5 cm behind, from the same side: flagged.
        assert!(former_cell_short_of(
            &mut map,
            sensor,
            Vector2::new(1.05, 0.001),
            0.1
        ));
        // 15 cm behind, outside the 10 cm window: stored.
        assert!(!former_cell_short_of(
            &mut map,
            sensor,
            Vector2::new(1.15, 0.001),
            0.1
        ));
        // In the known cell itself (a re-observation): stored.
        assert!(!former_cell_short_of(
            &mut map,
            sensor,
            Vector2::new(1.005, 0.002),
            0.1
        ));
        // Another bearing: nothing short of it.
        assert!(!former_cell_short_of(
            &mut map,
            sensor,
            Vector2::new(1.05, 0.2),
            0.1
        ));
        // A point in front of the known cell: nothing short of it either.
        assert!(!former_cell_short_of(
            &mut map,
            sensor,
            Vector2::new(0.95, 0.001),
            0.1
        ));
    }
}
