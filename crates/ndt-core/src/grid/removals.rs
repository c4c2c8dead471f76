//! A grid's count of the fine cells it has lost, with an identity.
//!
//! The §V filter keeps a record per map cell and must forget the records of
//! cells that left the grid by other means than its own deletions (the
//! odometry loop's map window, a caller's [`NdtGrid::remove_cells`]). Asking
//! the grid about every record at every periodic check was about 14 % of the
//! odometry helper's instructions (benches/SPEED_LOG.md, session 24). With
//! this count the filter tells "the grid lost only the cells I know of" from
//! "something else removed cells": equal stamps of one grid mean no cell left
//! it in between ([`crate::mapper::MapFilter::run_checks`]).

use std::sync::atomic::{AtomicU64, Ordering};

use super::NdtGrid;

/// Identities handed out so far (0 is never one).
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// Who a grid is (unique in the process: a clone is another grid, whose
/// removals are its own) and how many fine cells it has lost.
#[derive(Debug)]
pub(crate) struct Removals {
    id: u64,
    count: u64,
}

impl Removals {
    /// A new identity, nothing lost yet.
    pub(crate) fn new() -> Self {
        Self {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            count: 0,
        }
    }

    /// `n` more fine cells lost.
    pub(crate) fn add(&mut self, n: usize) {
        self.count = self.count.saturating_add(n as u64);
    }
}

/// Where one grid stands in its removals ([`NdtGrid::removal_stamp`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RemovalStamp {
    grid: u64,
    removed: u64,
}

impl RemovalStamp {
    /// The stamp of the same grid after `n` more cells left it.
    pub(crate) fn advanced(self, n: usize) -> Self {
        Self {
            removed: self.removed.saturating_add(n as u64),
            ..self
        }
    }

    /// Whether both stamps are of one grid.
    pub(crate) fn same_grid(self, other: Self) -> bool {
        self.grid == other.grid
    }
}

impl NdtGrid {
    /// This grid's identity and the number of fine cells it has lost so far
    /// (by [`NdtGrid::remove_cells`]): two equal stamps mean no cell left
    /// the grid in between. A clone is another grid.
    pub fn removal_stamp(&self) -> RemovalStamp {
        RemovalStamp {
            grid: self.removals.id,
            removed: self.removals.count,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use crate::{CellKey, NdtGrid, Pose2};

    #[test]
    fn the_stamp_moves_with_removals_only_and_a_clone_is_another_grid() {
        let mut grid = NdtGrid::new(0.02).unwrap();
        let start = grid.removal_stamp();
        let keys = grid
            .insert(&[[0.01, 0.01], [0.51, 0.01]], Pose2::identity())
            .unwrap();
        assert_eq!(grid.removal_stamp(), start, "inserts remove nothing");
        // A key without a cell is ignored and not counted.
        let absent = CellKey { ix: 400, iy: 400 };
        assert_eq!(grid.remove_cells(&[keys[0], absent]), 1);
        assert_eq!(grid.removal_stamp(), start.advanced(1));
        // Inside a deferral too.
        {
            let mut deferred = grid.deferral();
            assert_eq!(deferred.remove_cells(&keys[1..]), 1);
        }
        assert_eq!(grid.removal_stamp(), start.advanced(2));
        let copy = grid.clone();
        assert!(!copy.removal_stamp().same_grid(grid.removal_stamp()));
        assert!(grid.removal_stamp().same_grid(start));
    }
}
