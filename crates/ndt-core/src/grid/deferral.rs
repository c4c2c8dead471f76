//! Deferred upkeep of a grid's coarser levels: inside a deferral
//! ([`NdtGrid::deferral`]), inserts and removals change the fine level
//! (sums, occupancy, bounds) alone, and the coarser pyramid levels and the
//! prepared distributions of every fine cell they changed are brought up to
//! date once, when the last open deferral ends.
//!
//! The §V mapper inserts a scan, deletes the cells found free and those its
//! periodic checks drop, and the odometry loop's map window drops more, each
//! a change to the grid; its helper thread takes 8 scans at a time
//! ([`crate::mapworker`]). A coarse cell above several of those changes is
//! re-summed once instead of after each: on the first 3000 Intel scans the
//! helper's instructions fell by 13 % (benches/SPEED_LOG.md, session 19).
//! The result is the same bit for bit: a coarse cell is a function of the
//! fine cells below it ([`crate::pyramid`]), a kept distribution one of the
//! sums ([`crate::distributions`]).
//!
//! Inside a deferral only the fine level may be read: [`NdtGrid::stats`],
//! [`NdtGrid::occupancy`], [`NdtGrid::occupancy_probe`] (which reads the
//! occupancy, not the pyramid), [`NdtGrid::key_bounds`]; reading a coarser
//! level or matching is a bug, caught by debug assertions.

use std::ops::{Deref, DerefMut};

use super::NdtGrid;

/// A grid whose coarser levels wait for the end of this deferral (see the
/// module docs); it ends when dropped, also on unwinding.
pub(crate) struct Deferral<'a> {
    grid: &'a mut NdtGrid,
}

impl NdtGrid {
    /// Opens a [`Deferral`] on this grid.
    pub(crate) fn deferral(&mut self) -> Deferral<'_> {
        self.begin_deferral();
        Deferral { grid: self }
    }

    /// Opens a deferral that [`NdtGrid::end_deferral`] closes (for owners
    /// that hold the grid beside other state, see [`crate::Mapper`]).
    pub(crate) fn begin_deferral(&mut self) {
        self.deferring += 1;
    }

    /// Closes a deferral; the last one brings the coarser levels and the
    /// prepared distributions up to date.
    pub(crate) fn end_deferral(&mut self) {
        self.deferring = self.deferring.saturating_sub(1);
        if self.deferring == 0 && !self.pending.is_empty() {
            let touched = self.pyramid.refresh(&self.pending);
            // Emptied, its storage kept for the next deferral.
            self.pending.clear();
            self.update_prepared(&touched);
            self.pyramid.give_back(touched);
        }
    }
}

impl Drop for Deferral<'_> {
    fn drop(&mut self) {
        self.grid.end_deferral();
    }
}

impl Deref for Deferral<'_> {
    type Target = NdtGrid;
    fn deref(&self) -> &NdtGrid {
        self.grid
    }
}

impl DerefMut for Deferral<'_> {
    fn deref_mut(&mut self) -> &mut NdtGrid {
        self.grid
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::key::CellKey;
    use crate::se2::Pose2;
    use crate::testing::assert_same_grids as assert_same;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Inserts and removals inside (nested) deferrals leave the grid as the
    /// same calls one by one do: the coarser levels, the prepared
    /// distributions (kept, not rebuilt) and the bounds; inside, the fine
    /// level and the occupancy are already up to date.
    #[test]
    fn a_deferred_run_equals_the_calls_one_by_one() {
        let mut rng = StdRng::seed_from_u64(7);
        let mut eager = NdtGrid::new(0.02).unwrap();
        eager.insert(&[[0.0, 0.0]], Pose2::identity()).unwrap();
        for l in 0..eager.levels() {
            for options in crate::testing::GRID_OPTIONS {
                let _ = eager.distributions(l, options);
            }
        }
        let mut lazy = eager.clone();
        let mut copy_inside;
        for round in 0..12 {
            let mut ops = Vec::new();
            for _ in 0..rng.random_range(1..8) {
                if rng.random_bool(0.3) {
                    let keys: Vec<CellKey> =
                        eager.keys().filter(|_| rng.random_bool(0.2)).collect();
                    ops.push(Err(keys));
                } else {
                    // Clusters of 1–4 points (minority cells, cells
                    // crossing the 3-point bound), some removed again.
                    let mut pts = Vec::new();
                    for _ in 0..rng.random_range(1..30) {
                        let c = [rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5)];
                        for _ in 0..rng.random_range(1..5) {
                            pts.push([c[0] + rng.random_range(-0.03..0.03), c[1]]);
                        }
                    }
                    ops.push(Ok(pts));
                }
                // The eager grid's removals pick from its current cells.
                match ops.last().unwrap() {
                    Ok(pts) => {
                        eager.insert(pts, Pose2::identity()).unwrap();
                    }
                    Err(keys) => {
                        eager.remove_cells(keys);
                    }
                }
            }
            {
                let mut outer = lazy.deferral();
                for (i, op) in ops.iter().enumerate() {
                    // Every other call in a deferral of its own, nested.
                    let apply = |g: &mut NdtGrid| match op {
                        Ok(pts) => {
                            g.insert(pts, Pose2::identity()).unwrap();
                        }
                        Err(keys) => {
                            g.remove_cells(keys);
                        }
                    };
                    if i % 2 == 0 {
                        apply(&mut outer.deferral());
                    } else {
                        apply(&mut outer);
                    }
                }
                assert!(!outer.pending.is_empty(), "round {round}: nothing deferred");
                // The fine level is current inside.
                let mut occupied = outer.occupancy();
                for (k, s) in eager.cell_states() {
                    assert_eq!(outer.stats(k), Some(&s), "round {round}");
                    assert!(occupied.contains(k));
                }
                assert_eq!(outer.len(), eager.len(), "round {round}");
                // A copy made inside is brought up to date at once.
                copy_inside = NdtGrid::clone(&outer);
                assert!(copy_inside.pending.is_empty() && copy_inside.deferring == 0);
            }
            assert!(lazy.pending.is_empty());
            assert_eq!(lazy.deferring, 0);
            assert_same(&eager, &copy_inside);
            assert_same(&eager, &lazy);
            // The bounds grow with the inserts alike (a fresh grid's are
            // tight, so they are compared here only).
            assert_eq!(eager.key_bounds(), lazy.key_bounds(), "round {round}");
        }
        // And as a grid built from the same cells.
        let fresh = NdtGrid::from_cell_states(0.02, &eager.cell_states()).unwrap();
        assert_same(&fresh, &lazy);
    }
}
