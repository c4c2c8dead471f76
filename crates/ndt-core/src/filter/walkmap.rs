//! The map as the §V walks of one scan read it (steps b-2 and d): the grid,
//! a reader of its occupied cells and its occupancy probe, kept across the
//! scan's beams. Every beam starts at the sensor and the map does not change
//! until the scan is stored, so the words the first walks read answer most
//! reads of the later ones: the probe remembers them by block index modulo
//! 32 ([`crate::cellmask::CellMask::window_reader`]). Kept across the beams
//! with that memo, the odometry helper's instructions fell by 8 %
//! (benches/SPEED_LOG.md, session 25).

use nalgebra::Vector2;

use crate::cellmask::CellMaskReader;
use crate::filter::raywalk::walk_cells_in_skipping;
use crate::grid::NdtGrid;
use crate::key::CellKey;
use crate::occupancy::OccupancyProbe;

/// A grid read by a scan's §V walks (see the module docs).
#[derive(Debug)]
pub struct WalkMap<'a> {
    grid: &'a NdtGrid,
    occupied: CellMaskReader<'a>,
    probe: OccupancyProbe<'a>,
}

impl<'a> WalkMap<'a> {
    /// The readers of `grid` for one scan's walks.
    pub fn new(grid: &'a NdtGrid) -> Self {
        Self {
            grid,
            occupied: grid.occupancy(),
            probe: grid.occupancy_probe(),
        }
    }

    /// The grid read.
    pub fn grid(&self) -> &'a NdtGrid {
        self.grid
    }

    /// Walks the cells from `from` to `to` (map frame \[m\]) within the
    /// grid's region ([`walk_cells_in_skipping`] with the grid's probe),
    /// calling `visit(key, occupied)` on each cell the walk does not skip
    /// until it returns `false`. Every occupied cell of the segment is
    /// visited, in order; empty blocks are crossed without visits, and the
    /// walk ends in an empty block holding `to`'s cell.
    pub fn walk(
        &mut self,
        from: Vector2<f64>,
        to: Vector2<f64>,
        mut visit: impl FnMut(CellKey, bool) -> bool,
    ) {
        let Self {
            grid,
            occupied,
            probe,
        } = self;
        walk_cells_in_skipping(
            from,
            to,
            grid.cell_size(),
            grid.key_bounds(),
            probe,
            |key, _, _| visit(key, occupied.contains(key)),
        );
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::filter::raywalk::walk_cells_in;
    use crate::Pose2;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// One map read by thousands of walks from a few sensor positions, over
    /// a map wider than the probe's 20 m window (so its memo's slots are
    /// taken over and over), visits the occupied cells of every walk in the
    /// cell-by-cell walk's order, and them only as occupied.
    #[test]
    fn a_map_kept_across_walks_sees_every_occupied_cell() {
        let mut rng = StdRng::seed_from_u64(11);
        let mut grid = NdtGrid::new(0.02).unwrap();
        let mut pts: Vec<[f64; 2]> = Vec::new();
        for _ in 0..60 {
            let (x, y) = (rng.random_range(-30.0..30.0), rng.random_range(-30.0..30.0));
            let a: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            for i in 0..rng.random_range(20..300) {
                let t = f64::from(i) * 0.01;
                pts.push([x + t * a.cos(), y + t * a.sin()]);
            }
        }
        grid.insert(&pts, Pose2::identity()).unwrap();
        let occupied = |k: CellKey| grid.stats(k).is_some();
        let mut map = WalkMap::new(&grid);
        let mut met = 0;
        for sensor in 0..12 {
            let s = Vector2::new(rng.random_range(-25.0..25.0), rng.random_range(-25.0..25.0));
            for beam in 0..200 {
                let end = if beam % 2 == 0 {
                    let p = pts[rng.random_range(0..pts.len())];
                    Vector2::new(p[0], p[1])
                } else {
                    Vector2::new(rng.random_range(-35.0..35.0), rng.random_range(-35.0..35.0))
                };
                let mut want = Vec::new();
                walk_cells_in(s, end, 0.02, grid.key_bounds(), |k, _, _| {
                    if occupied(k) {
                        want.push(k);
                    }
                    true
                });
                let mut got = Vec::new();
                map.walk(s, end, |k, occ| {
                    assert_eq!(occ, occupied(k), "{k:?}");
                    if occ {
                        got.push(k);
                    }
                    true
                });
                assert_eq!(got, want, "sensor {sensor} beam {beam}");
                met += usize::from(!want.is_empty());
            }
        }
        assert!(met > 1000, "{met} walks met an occupied cell");
    }
}
