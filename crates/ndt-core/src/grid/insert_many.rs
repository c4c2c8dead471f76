//! Many scans into a grid in one call ([`NdtGrid::insert_many`]): a map
//! built from a log whose poses are known (ground truth, a finished SLAM run,
//! an optimised trajectory), or a loop that collects a few scans before it
//! updates its map.
//!
//! eq. (6) is applied to each scan in order, inside one deferral
//! ([`super::deferral`]): the fine cells take every scan's points at once,
//! and each coarser cell above them, with the prepared distributions of
//! every level, is brought up to date once at the end, however many scans
//! of the batch changed it. Consecutive scans of a log see mostly the same
//! surfaces, so that upkeep, most of a single insert's work (benches/SPEED_LOG.md,
//! session 36: the re-sums and distributions are 80 % of an
//! insert's instructions), is shared by the batch. The grid that results is
//! the one the inserts one by one give, bit for bit (a coarse cell is a
//! function of the fine cells, a distribution one of the sums).

use super::{NdtGrid, StagedScan};
use crate::error::{check_pose_count, in_scan, Result};
use crate::se2::Pose2;

impl NdtGrid {
    /// eq. (6) for every scan: `scans[i]` (scan-frame points \[m\]) seen
    /// from `poses[i]` (`T_map_scan`), in order. The grid afterwards equals,
    /// bit for bit, the one that [`NdtGrid::insert`] gives scan by scan (its
    /// levels, distributions, bounds and occupancy), but the coarser levels
    /// and the prepared distributions are updated once for the whole batch.
    ///
    /// All-or-nothing: every scan is checked as [`NdtGrid::insert`] checks
    /// it before the grid changes ([`crate::NdtError::InScan`] names the first scan
    /// rejected), and a number of poses other than one per scan is an error
    /// ([`crate::NdtError::PoseCount`]). The check stages a scan (eq. 2) only
    /// when a bound on its reach does not already keep it within the lattice
    /// (see `check_reach`), and the insert stages it again. Memory
    /// beyond the grid's: one scan's staged points, and the keys of the fine
    /// cells each scan changed (8 bytes a cell and scan), which wait for the
    /// batch's end. An empty batch changes nothing.
    pub fn insert_many(&mut self, scans: &[&[[f64; 2]]], poses: &[Pose2]) -> Result<()> {
        check_pose_count("poses", scans.len(), poses.len())?;
        if let ([points], [pose]) = (scans, poses) {
            // One scan: an insert, staged once and without a deferral.
            let keys = self.insert(points, *pose).map_err(in_scan(0))?;
            self.give_back(keys);
            return Ok(());
        }
        let mut spare = StagedScan::default();
        for (index, (points, pose)) in scans.iter().zip(poses).enumerate() {
            if !self.check_reach(points, *pose).map_err(in_scan(index))? {
                spare = self.stage(points, *pose, spare).map_err(in_scan(index))?;
            }
        }
        let mut grid = self.deferral();
        for (points, pose) in scans.iter().zip(poses) {
            // Checked above, with the same inputs: staging cannot fail here,
            // and should it, the grid keeps the scans staged so far (each a
            // whole scan) and is brought up to date when the deferral ends.
            spare = grid.stage(points, *pose, spare)?;
            let keys = grid.insert_staged(&spare);
            grid.give_back(keys);
        }
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::testing::{assert_same_grids, GRID_OPTIONS};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Scans of clustered points (minority cells among them) from poses
    /// close to each other, as a log's consecutive scans are.
    fn scans(rng: &mut StdRng, n: usize) -> (Vec<Vec<[f64; 2]>>, Vec<Pose2>) {
        let mut scans = Vec::new();
        let mut poses = Vec::new();
        for i in 0..n {
            let mut pts = Vec::new();
            for _ in 0..rng.random_range(0..40) {
                let c = [rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5)];
                for _ in 0..rng.random_range(1..5) {
                    pts.push([c[0] + rng.random_range(-0.03..0.03), c[1]]);
                }
            }
            scans.push(pts);
            let t = i as f64 * 0.05;
            poses.push(Pose2::new(0.1 * t, -0.05 * t, 0.02 * t));
        }
        (scans, poses)
    }

    /// A grid with prepared distributions on every level, for the inserts
    /// to keep up to date.
    fn prepared_grid() -> NdtGrid {
        let mut grid = NdtGrid::new(0.02).unwrap();
        grid.insert(&[[0.0, 0.0], [0.01, 0.0], [0.3, 0.2]], Pose2::identity())
            .unwrap();
        for l in 0..grid.levels() {
            for options in GRID_OPTIONS {
                let _ = grid.distributions(l, options);
            }
        }
        grid
    }

    /// Every level's sums and prepared distributions, the bounds, bit for bit.
    fn assert_same(a: &NdtGrid, b: &NdtGrid) {
        assert_eq!(a.key_bounds(), b.key_bounds());
        assert_same_grids(a, b);
    }

    #[test]
    fn a_batch_equals_the_inserts_one_by_one() {
        let mut rng = StdRng::seed_from_u64(11);
        let mut one_by_one = prepared_grid();
        let mut batched = prepared_grid();
        for round in 0..6 {
            let n = rng.random_range(1..12);
            let (scans, poses) = scans(&mut rng, n);
            for (pts, pose) in scans.iter().zip(&poses) {
                one_by_one.insert(pts, *pose).unwrap();
            }
            let views: Vec<&[[f64; 2]]> = scans.iter().map(Vec::as_slice).collect();
            batched.insert_many(&views, &poses).unwrap();
            assert!(batched.pending.is_empty(), "round {round}");
            assert_same(&one_by_one, &batched);
        }
    }

    /// Far from the origin, where the quick bound on a scan's reach does not
    /// hold, a batch accepts and rejects what the inserts do, with their errors.
    #[test]
    fn far_scans_are_checked_as_insert_checks_them() {
        let limit = NdtGrid::new(0.02).unwrap().coordinate_limit();
        let cases = [
            // (point, pose): within the bound, beyond it but inside the
            // lattice, beyond the lattice by the point or by the pose.
            ([0.2 * limit, 0.0], Pose2::new(0.2 * limit, 0.0, 0.0)),
            ([0.6 * limit, 0.0], Pose2::new(0.0, 0.3 * limit, 2.0)),
            ([0.0, 0.45 * limit], Pose2::new(0.5 * limit, 0.0, 0.0)),
            ([0.6 * limit, 0.0], Pose2::new(0.6 * limit, 0.0, 0.0)),
            ([0.0, 1.2 * limit], Pose2::identity()),
            ([1.0, 0.0], Pose2::new(-1.1 * limit, 0.0, 0.3)),
        ];
        for (i, (point, pose)) in cases.into_iter().enumerate() {
            let mut batched = prepared_grid();
            let scans = [[[0.0, 0.0], point]];
            let single = prepared_grid().insert(&scans[0], pose).map(|_| ());
            let views: Vec<&[[f64; 2]]> = vec![&[[0.1, 0.1]], &scans[0]];
            let poses = [Pose2::identity(), pose];
            match single {
                Ok(()) => {
                    // The same inserts, in the batch's order.
                    let mut ordered = prepared_grid();
                    ordered.insert(&[[0.1, 0.1]], Pose2::identity()).unwrap();
                    ordered.insert(&scans[0], pose).unwrap();
                    batched.insert_many(&views, &poses).unwrap();
                    assert_same(&ordered, &batched);
                    assert!(i < 3, "case {i} was expected to fail");
                }
                Err(e) => {
                    let got = batched.insert_many(&views, &poses).unwrap_err();
                    assert_eq!(got.to_string(), format!("scan 1: {e}"), "case {i}");
                    assert_eq!(batched.cell_states(), prepared_grid().cell_states());
                    assert!(i >= 3, "case {i} was expected to pass");
                }
            }
        }
    }

    #[test]
    fn a_rejected_scan_leaves_the_grid_unchanged() {
        let mut rng = StdRng::seed_from_u64(12);
        let mut grid = prepared_grid();
        let (mut scans, mut poses) = scans(&mut rng, 5);
        poses[3] = Pose2::identity();
        let before = grid.cell_states();
        scans[3].push([f64::NAN, 0.0]);
        let bad = scans[3].len() - 1;
        let views: Vec<&[[f64; 2]]> = scans.iter().map(Vec::as_slice).collect();
        let err = grid.insert_many(&views, &poses).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("scan 3: points: expected finite values, got NaN at index {bad}")
        );
        let far = [[1e9, 0.0]];
        let mut views = views;
        views[3] = &far;
        let err = grid.insert_many(&views, &poses).unwrap_err();
        assert_eq!(
            err.to_string(),
            "scan 3: points: point 0 at (1e9, 0) m is outside the grid's range of \
             ±21474836.48 m (cell index would overflow)"
        );
        let err = grid.insert_many(&views[..2], &poses).unwrap_err();
        assert_eq!(
            err.to_string(),
            "poses: expected 2 poses (one per scan), got 5"
        );
        assert_eq!(grid.cell_states(), before);
        assert!(grid.pending.is_empty() && grid.deferring == 0);
        // An empty batch changes nothing.
        grid.insert_many(&[], &[]).unwrap();
        assert_eq!(grid.cell_states(), before);
    }
}
