//! Which of the §V filter's per-cell records may have lost their cell.
//!
//! A record lives as long as its cell holds points. The filter deletes
//! cells with their records (steps b-1, c, d), but cells also leave the grid
//! by other means: [`crate::Mapper::remove_cells`] (the odometry loop's map
//! window, every inserted scan) and whoever else holds the grid
//! ([`crate::mapper::MapFilter`] works on a grid its caller keeps, e.g. the
//! Python binding's shared one). Each periodic check forgets the records whose cells
//! are gone. Asking the grid about every record there cost about 14 % of the
//! odometry helper's instructions (benches/SPEED_LOG.md, session 24); this
//! remembers the keys the mapper removed and the grid's removal count
//! ([`NdtGrid::removal_stamp`]), so that a check asks about those keys only
//! when no other cell left the grid, and about every record otherwise. The
//! records kept are the same either way: every record's cell held points at
//! the last check or was hit since (a hit holds points), and a cell can
//! only lose them by a removal.

use crate::filter::observation::CellTable;
use crate::grid::{NdtGrid, RemovalStamp};
use crate::key::CellKey;

/// The keys removed from the grid since the last check whose records were
/// kept, and the grid's stamp as the filter expects it.
#[derive(Debug, Clone, Default)]
pub(crate) struct StaleRecords {
    /// Keys the mapper removed since the last check (some may hold points
    /// again).
    removed: Vec<CellKey>,
    /// The grid's [`NdtGrid::removal_stamp`] at the last check, advanced by
    /// every removal made or reported since; `None`: unknown (a new or
    /// restored filter, another grid, an overflow of `removed`).
    expected: Option<RemovalStamp>,
}

impl StaleRecords {
    /// The filter works on `grid` now: a grid other than the last check's
    /// leaves nothing known.
    pub(crate) fn follow(&mut self, grid: &NdtGrid) {
        if self
            .expected
            .is_some_and(|e| !e.same_grid(grid.removal_stamp()))
        {
            self.unknown();
        }
    }

    /// The filter deleted `n` cells, records and all, from the grid whose
    /// stamp was `before`.
    pub(crate) fn deleted(&mut self, before: RemovalStamp, n: usize) {
        self.advance(before, n);
    }

    /// The mapper removed `n` cells of `keys` from the grid whose stamp was
    /// `before`; their records are kept until the next check. More kept keys
    /// than `limit` (the records' number: a pass over all of them costs no
    /// more) leave nothing known.
    pub(crate) fn removed(
        &mut self,
        before: RemovalStamp,
        keys: &[CellKey],
        n: usize,
        limit: usize,
    ) {
        if !self.advance(before, n) || n == 0 {
            return;
        }
        if self.removed.len() + keys.len() > limit {
            self.unknown();
        } else {
            self.removed.extend_from_slice(keys);
        }
    }

    /// `n` cells left the grid whose stamp was `before`: `false`, and
    /// nothing known, when that is not the stamp expected.
    fn advance(&mut self, before: RemovalStamp, n: usize) -> bool {
        if self.expected != Some(before) {
            self.unknown();
            return false;
        }
        self.expected = Some(before.advanced(n));
        true
    }

    /// Forgets the records of `table` whose cells `grid` no longer holds
    /// (see the module docs); from now on the grid is expected as it is.
    pub(crate) fn forget(&mut self, table: &mut CellTable, grid: &NdtGrid) {
        let now = grid.removal_stamp();
        let mut occupied = grid.occupancy();
        if self.expected == Some(now) {
            for k in self.removed.drain(..) {
                if !occupied.contains(k) {
                    table.remove(&k);
                }
            }
        } else {
            table.retain(|k, _| occupied.contains(*k));
            self.removed.clear();
        }
        self.expected = Some(now);
    }

    /// Nothing known: the next check asks about every record.
    fn unknown(&mut self) {
        self.removed = Vec::new();
        self.expected = None;
    }
}

/// The integration tests' ray caster, shared.
#[cfg(test)]
#[path = "../../tests/common/mod.rs"]
mod fixtures;

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    use super::fixtures::{room, scan as cast_scan};
    use super::StaleRecords;
    use crate::key::CellKey;
    use crate::mapper::{Mapper, MapperOptions};
    use crate::se2::Pose2;

    /// Ranges and angles of 181 beams over 180° from `pose` in the fixtures'
    /// room, with a 30 cm box in it until scan 40 (so that step d clears it)
    /// and 5 mm noise.
    fn scan(pose: Pose2, k: usize, rng: &mut StdRng) -> (Vec<f64>, Vec<f64>) {
        let mut walls = room();
        if k < 40 {
            walls.extend([([0.5, 0.5], [0.8, 0.5]), ([0.8, 0.5], [0.8, 0.8])]);
        }
        let pts = cast_scan(&walls, pose, 181, std::f64::consts::PI, 0.005, rng.random());
        pts.iter()
            .map(|p| (p[0].hypot(p[1]), p[1].atan2(p[0])))
            .unzip()
    }

    /// A mapper that asks the grid about the keys it removed keeps the same
    /// records, and the same map, as one that asks about every record at
    /// every check: under its own removals (a map window's), removals made
    /// on its grid directly, and a grid swapped for a copy.
    #[test]
    fn asking_about_the_removed_keys_keeps_the_records_of_a_full_pass() {
        let mut rng = StdRng::seed_from_u64(9);
        let options = MapperOptions::default();
        let mut fast = Mapper::new(0.02, options).unwrap();
        let mut full = fast.clone();
        let mut partial_checks = 0;
        for k in 0..90 {
            let t = k as f64 * 0.02;
            let pose = Pose2::new(-1.0 + 0.6 * t.sin(), -0.8 + 0.4 * t, 0.3 * t.cos());
            let (ranges, angles) = scan(pose, k, &mut rng);
            // The twin forgets what it knew: its next check asks about
            // every record.
            full.filter.stale = StaleRecords::default();
            partial_checks += usize::from(fast.filter.stale.expected.is_some());
            for m in [&mut fast, &mut full] {
                m.insert_scan(&ranges, &angles, pose).unwrap();
            }
            let mut keys: Vec<CellKey> = fast.grid().keys().collect();
            keys.sort_unstable();
            let pick = |every: usize, rng: &mut StdRng| -> Vec<CellKey> {
                let start = rng.random_range(0..every);
                keys.iter().copied().skip(start).step_by(every).collect()
            };
            if k % 4 == 1 {
                // The mapper's own removals (as the loop's window makes).
                let gone = pick(9, &mut rng);
                assert_eq!(fast.remove_cells(&gone), full.remove_cells(&gone));
            }
            if k % 11 == 5 {
                // Someone else's, on the grid directly.
                let gone = pick(13, &mut rng);
                assert_eq!(fast.grid.remove_cells(&gone), full.grid.remove_cells(&gone));
            }
            if k == 60 {
                // Another grid (a copy), then the copy's own removals.
                fast.grid = fast.grid.clone();
                let gone = pick(17, &mut rng);
                assert_eq!(fast.remove_cells(&gone), full.remove_cells(&gone));
            }
            assert_eq!(
                fast.filter.cell_records(),
                full.filter.cell_records(),
                "scan {k}"
            );
            assert_eq!(
                fast.grid().cell_states(),
                full.grid().cell_states(),
                "scan {k}"
            );
        }
        // Most checks took the short way.
        assert!(partial_checks > 60, "{partial_checks} of 90");
        assert!(fast.filter.tracked_cells() > 100);
        // The filter alone, on another grid between two checks of its own:
        // the records of that grid's cells go at the next check of this one.
        let (mut grid, mut filter) = fast.into_parts();
        let (mut twin_grid, mut twin) = full.into_parts();
        filter.run_checks(&mut grid);
        twin.run_checks(&mut twin_grid);
        let mut other = crate::NdtGrid::new(0.02).unwrap();
        let pose = Pose2::new(1.2, 1.1, 2.5);
        let (ranges, angles) = scan(pose, 99, &mut rng);
        filter
            .insert_scan(&mut other, &ranges, &angles, pose)
            .unwrap();
        twin.insert_scan(&mut other.clone(), &ranges, &angles, pose)
            .unwrap();
        twin.stale = StaleRecords::default();
        assert_eq!(
            filter.run_checks(&mut grid),
            twin.run_checks(&mut twin_grid)
        );
        assert_eq!(filter.cell_records(), twin.cell_records());
        assert!(filter
            .cell_records()
            .iter()
            .all(|(k, _)| grid.stats(*k).is_some()));
    }
}
