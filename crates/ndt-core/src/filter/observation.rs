//! §V-B(3) "Surface of wall", step c: false detections on walls and big
//! objects tend to be observed only a few times, so every cell counts the
//! scans that hit it and, once every `check_interval` scans (the paper:
//! every third scan), the cells seen in fewer than `min_observations` scans
//! are deleted. This file also holds the per-cell bookkeeping the other
//! steps read ([`CellInfo`]).
//!
//! With `support` (ours, on by default) a rarely seen cell is kept when one
//! of its 8 neighbours is established (seen in at least `min_observations`
//! scans): at 2 cm a far wall is hit sparsely and each of its cells may be
//! hit in a single scan while the wall as a whole is seen in every scan;
//! speckle, by contrast, lies off the surface, away from established cells.

use rustc_hash::FxHashMap;

use crate::key::CellKey;

/// What the filter remembers about one map cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CellInfo {
    /// Scan number (1-based) of the first scan that hit the cell.
    pub first_seen: u64,
    /// Scan number of the latest scan that hit the cell.
    pub last_seen: u64,
    /// Number of scans that hit the cell (step c counts these, not points).
    pub observations: u32,
    /// Of those, scans in which the hit came from a small cluster (a-1).
    pub small_observations: u32,
    /// §V-B(2) b-1: some hit came from Area 1 (within the reliable range).
    pub seen_in_area1: bool,
}

impl CellInfo {
    /// A cell first hit by scan `scan`.
    pub fn new(scan: u64) -> Self {
        Self {
            first_seen: scan,
            last_seen: 0,
            observations: 0,
            small_observations: 0,
            seen_in_area1: false,
        }
    }

    /// A cell that was in the map before the filter knew it (points inserted
    /// into the grid directly): treated as an established, big object.
    pub fn established(scan: u64, min_observations: u32) -> Self {
        Self {
            first_seen: scan,
            last_seen: 0,
            observations: min_observations,
            small_observations: 0,
            seen_in_area1: true,
        }
    }

    /// Records that scan `scan` hit the cell; `small`: the hit came from a
    /// small cluster; `area1`: it came from within the reliable range. A
    /// second hit from the same scan only updates the flags.
    pub fn observe(&mut self, scan: u64, small: bool, area1: bool) {
        if self.last_seen != scan {
            self.last_seen = scan;
            self.observations = self.observations.saturating_add(1);
            if small {
                self.small_observations = self.small_observations.saturating_add(1);
            }
        }
        self.seen_in_area1 |= area1;
    }

    /// The cell belongs to a small (sub-grid scale) object: most of the scans
    /// that hit it saw it as part of a small cluster (a-1).
    pub fn is_small(&self) -> bool {
        // In u64: a restored map may count up to u32::MAX scans, and twice
        // that overflows u32.
        2 * u64::from(self.small_observations) > u64::from(self.observations)
    }
}

/// The per-cell bookkeeping of the whole map.
pub type CellTable = FxHashMap<CellKey, CellInfo>;

/// `true` when the periodic checks (b-1 and c) run after scan `scan`
/// (1-based): every `interval`-th scan.
pub fn check_due(scan: u64, interval: u32) -> bool {
    interval > 0 && scan.is_multiple_of(u64::from(interval))
}

/// §V step c: the cells that scan `scan`'s check deletes: those that have
/// had at least `interval` scans to be observed (first seen `interval − 1` or
/// more scans ago) and were observed in fewer than `min_observations` scans
/// — with `support`, only those without an established 8-neighbour. Sorted,
/// so results are deterministic.
pub fn rarely_seen(
    table: &CellTable,
    scan: u64,
    interval: u32,
    min_observations: u32,
    support: bool,
) -> Vec<CellKey> {
    let established = |k: CellKey| {
        table
            .get(&k)
            .is_some_and(|c| c.observations >= min_observations)
    };
    let supported = |k: CellKey| {
        (-1..=1).any(|dy| (-1..=1).any(|dx| (dx, dy) != (0, 0) && established(k.offset(dx, dy))))
    };
    super::sorted_keys(table.iter().map(|(&k, c)| (k, c)), |k, c| {
        scan + 1 >= c.first_seen + u64::from(interval)
            && c.observations < min_observations
            && !(support && supported(k))
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// A majority of small observations, also at counts whose double does
    /// not fit a u32 (a restored map's, up to u32::MAX).
    #[test]
    fn a_small_majority_at_any_count() {
        let info = |observations, small_observations| CellInfo {
            observations,
            small_observations,
            ..CellInfo::new(1)
        };
        assert!(info(3, 2).is_small());
        assert!(!info(4, 2).is_small());
        assert!(info(u32::MAX, 1 << 31).is_small());
        assert!(!info(u32::MAX, (1 << 31) - 1).is_small());
        assert!(info(u32::MAX, u32::MAX).is_small());
    }

    #[test]
    fn c_deletes_cells_seen_once_after_a_full_window() {
        let mut table = CellTable::default();
        let key = |i| CellKey { ix: 3 * i, iy: 0 };
        // Cell 0: a wall seen in scans 1, 2, 3. Cell 1: speckle in scan 1.
        // Cell 2: new in scan 3 (too young to judge at scan 3).
        let next_to_wall = CellKey { ix: 1, iy: 1 };
        table
            .entry(next_to_wall)
            .or_insert(CellInfo::new(1))
            .observe(1, false, false);
        for scan in 1..=3 {
            table
                .entry(key(0))
                .or_insert(CellInfo::new(scan))
                .observe(scan, false, false);
        }
        table
            .entry(key(1))
            .or_insert(CellInfo::new(1))
            .observe(1, false, false);
        table
            .entry(key(2))
            .or_insert(CellInfo::new(3))
            .observe(3, false, false);
        assert!(!check_due(2, 3) && check_due(3, 3) && check_due(6, 3));
        assert_eq!(
            rarely_seen(&table, 3, 3, 2, false),
            vec![next_to_wall, key(1)]
        );
        // At scan 6 cell 2 has had scans 3..6 and was seen once: deleted.
        assert_eq!(
            rarely_seen(&table, 6, 3, 2, false),
            vec![next_to_wall, key(1), key(2)]
        );
        // With support, the cell next to the established wall cell stays.
        assert_eq!(rarely_seen(&table, 6, 3, 2, true), vec![key(1), key(2)]);
    }

    #[test]
    fn observations_count_scans_not_points() {
        let mut c = CellInfo::new(4);
        c.observe(4, true, false);
        c.observe(4, true, true);
        assert_eq!(
            (c.observations, c.small_observations, c.seen_in_area1),
            (1, 1, true)
        );
        assert!(c.is_small());
        c.observe(5, false, false);
        c.observe(6, false, false);
        assert_eq!(c.observations, 3);
        assert!(!c.is_small());
    }
}
