//! The odometry loop's memory bound: a map that keeps only the cells hit by
//! its last `W` scans (a cell hit again stays, with all its points), so at
//! most `W × B` cells for `B`-beam scans however long the run.

use std::collections::VecDeque;

use rustc_hash::FxHashMap;

use crate::key::CellKey;

/// Which scan last hit each cell, and the cells of each of the last scans.
#[derive(Debug, Clone, Default)]
pub struct CellWindow {
    /// Scans recorded so far.
    scans: u64,
    /// Number of the scan that last hit each cell (only with a window).
    stamps: FxHashMap<CellKey, u64>,
    /// Cells hit by each of the last scans, oldest first.
    history: VecDeque<(u64, Vec<CellKey>)>,
}

impl CellWindow {
    /// Records a scan that hit the cells `touched`, keeping `size` scans (0 =
    /// every scan, nothing recorded); returns the cells no kept scan hits
    /// any more, which the map must drop.
    pub fn record(&mut self, touched: Vec<CellKey>, size: usize) -> Vec<CellKey> {
        self.scans += 1;
        if size == 0 {
            return Vec::new();
        }
        let n = self.scans;
        for &key in &touched {
            self.stamps.insert(key, n);
        }
        self.history.push_back((n, touched));
        // The stale cells are kept in the leaving scan's own vector (no
        // vector grows: on a helper thread, growing one could wait for the
        // allocator's lock, benches/SPEED_LOG.md, session 27).
        let mut stale = Vec::new();
        while self.history.len() > size {
            let Some((m, mut keys)) = self.history.pop_front() else {
                break;
            };
            keys.retain(|key| {
                let last = self.stamps.get(key) == Some(&m);
                if last {
                    self.stamps.remove(key);
                }
                last
            });
            if stale.is_empty() {
                stale = keys;
            } else {
                stale.extend_from_slice(&keys);
            }
        }
        stale
    }

    /// Scans recorded so far.
    pub fn scans(&self) -> u64 {
        self.scans
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn k(ix: i32) -> CellKey {
        CellKey { ix, iy: 0 }
    }

    #[test]
    fn drops_exactly_the_cells_no_kept_scan_hits() {
        let mut w = CellWindow::default();
        assert!(w.record(vec![k(1), k(2)], 2).is_empty());
        assert!(w.record(vec![k(2), k(3)], 2).is_empty());
        // Scan 1 leaves: cell 1 was hit by it alone, cell 2 again by scan 2.
        assert_eq!(w.record(vec![k(4)], 2), vec![k(1)]);
        assert_eq!(w.record(vec![k(4)], 2), vec![k(2), k(3)]);
        assert_eq!(w.scans(), 4);
        // Without a window nothing is dropped or kept.
        let mut all = CellWindow::default();
        for _ in 0..5 {
            assert!(all.record(vec![k(1)], 0).is_empty());
        }
        assert!(all.history.is_empty() && all.stamps.is_empty());
    }
}
