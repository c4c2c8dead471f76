//! A grid's exact state, for saving and loading: the fine cells' sums (the
//! pyramid's coarser levels are rebuilt from them, exactly).

use super::NdtGrid;
use crate::cell::CellStats;
use crate::error::{NdtError, Result};
use crate::key::{CellKey, MAX_INDEX};

/// Largest point count a stored cell may have: far beyond any real map
/// (2^62 points), and far enough from `u64::MAX` that adding scans cannot
/// overflow.
pub const MAX_CELL_COUNT: u64 = 1 << 62;

impl NdtGrid {
    /// The exact state of every cell, sorted by key: its index and its eq. (6)
    /// sums about the cell's own centre (the grid's internal representation,
    /// see [`CellStats`]). [`NdtGrid::from_cell_states`] rebuilds a grid that
    /// is bit for bit the same.
    pub fn cell_states(&self) -> Vec<(CellKey, CellStats)> {
        let mut out: Vec<(CellKey, CellStats)> = self.fine().iter().map(|(k, &s)| (k, s)).collect();
        out.sort_unstable_by_key(|(k, _)| *k);
        out
    }

    /// A grid of cells of `cell_size` metres with the default pyramid
    /// ([`super::DEFAULT_LEVELS`]) holding exactly `states` (as returned by
    /// [`NdtGrid::cell_states`]); the coarser levels are summed from them.
    ///
    /// Errors on an invalid cell size, and on a cell with a count of 0 or
    /// beyond [`MAX_CELL_COUNT`], a non-finite sum, an index beyond
    /// ±[`MAX_INDEX`], or a key given twice.
    pub fn from_cell_states(cell_size: f64, states: &[(CellKey, CellStats)]) -> Result<Self> {
        Self::from_cell_states_with_levels(cell_size, super::DEFAULT_LEVELS, states)
    }

    /// [`NdtGrid::from_cell_states`] with `levels` pyramid levels (see
    /// [`NdtGrid::with_levels`]).
    pub fn from_cell_states_with_levels(
        cell_size: f64,
        levels: usize,
        states: &[(CellKey, CellStats)],
    ) -> Result<Self> {
        let mut grid = NdtGrid::with_levels(cell_size, levels)?;
        let mut seen = rustc_hash::FxHashSet::default();
        for (index, (key, stats)) in states.iter().enumerate() {
            let bad = |reason| Err(NdtError::InvalidCell { index, reason });
            if key.ix.abs() >= MAX_INDEX || key.iy.abs() >= MAX_INDEX {
                return bad("has an index beyond +-2**30");
            }
            if stats.count == 0 {
                return bad("has a count of 0 (empty cells are not stored)");
            }
            if stats.count > MAX_CELL_COUNT {
                return bad("has a count beyond 2**62");
            }
            let finite = stats.sum.iter().chain(stats.scatter.iter());
            if !finite.into_iter().all(|v| v.is_finite()) {
                return bad("has a non-finite sum");
            }
            if !seen.insert(*key) {
                return bad("repeats the index of an earlier cell");
            }
        }
        grid.pyramid.set_fine(states);
        Ok(grid)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::{MatchOptions, Pose2};

    fn line(n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| [0.5 + 0.003 * i as f64, 0.01 * (i % 7) as f64])
            .collect()
    }

    #[test]
    fn removing_cells_updates_the_prepared_distributions() {
        let mut grid = NdtGrid::new(0.02).unwrap();
        let pts = line(200);
        grid.insert(&pts, Pose2::identity()).unwrap();
        let opts = MatchOptions::default();
        // Prepare the distributions, then remove half of the cells.
        let _ = grid.score_terms(&pts, Pose2::identity(), &opts);
        let states = grid.cell_states();
        let half: Vec<CellKey> = states.iter().step_by(2).map(|(k, _)| *k).collect();
        assert_eq!(grid.remove_cells(&half), half.len());
        assert_eq!(grid.remove_cells(&half), 0);
        assert_eq!(grid.len(), states.len() - half.len());
        // The incrementally updated distributions equal freshly built ones.
        let kept: Vec<_> = grid.cell_states();
        let fresh = NdtGrid::from_cell_states(0.02, &kept).unwrap();
        let a = grid
            .score_terms(&pts, Pose2::new(0.003, -0.002, 0.01), &opts)
            .unwrap();
        let b = fresh
            .score_terms(&pts, Pose2::new(0.003, -0.002, 0.01), &opts)
            .unwrap();
        assert_eq!(a.matched, b.matched);
        assert!((a.score - b.score).abs() <= 1e-9 * b.score.abs().max(1.0));
    }

    #[test]
    fn state_round_trip_is_bit_identical() {
        let mut grid = NdtGrid::new(0.05).unwrap();
        grid.insert(&line(300), Pose2::new(-12.3, 4.56, 0.7))
            .unwrap();
        let states = grid.cell_states();
        let back = NdtGrid::from_cell_states(0.05, &states).unwrap();
        assert_eq!(back.cell_states(), states);
        assert_eq!(back.cells(), grid.cells());
    }

    #[test]
    fn invalid_states_are_rejected_with_the_cell_index() {
        let key = CellKey { ix: 1, iy: 2 };
        let mut good = CellStats::default();
        good.add_point(nalgebra::Vector2::new(0.001, 0.002));
        let empty = CellStats::default();
        let err = NdtGrid::from_cell_states(0.02, &[(key, good), (key, good)]);
        assert_eq!(
            err.err().map(|e| e.to_string()),
            Some("cells: cell 1 repeats the index of an earlier cell".into())
        );
        let err = NdtGrid::from_cell_states(0.02, &[(key, empty)]);
        assert!(matches!(err, Err(NdtError::InvalidCell { index: 0, .. })));
        let far = CellKey {
            ix: MAX_INDEX,
            iy: 0,
        };
        let err = NdtGrid::from_cell_states(0.02, &[(far, good)]);
        assert!(matches!(err, Err(NdtError::InvalidCell { index: 0, .. })));
        let mut nan = good;
        nan.sum.x = f64::NAN;
        let err = NdtGrid::from_cell_states(0.02, &[(key, nan)]);
        assert!(matches!(err, Err(NdtError::InvalidCell { index: 0, .. })));
    }
}
