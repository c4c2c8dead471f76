//! A [`MapFilter`]'s exact state, for saving and loading: its options, its
//! per-cell records, the scan counter and the removal counters, checked for
//! consistency on the way in.

use super::{MapFilter, MapperOptions, RemovalCounts};
use crate::error::{NdtError, Result};
use crate::filter::observation::{CellInfo, CellTable};
use crate::key::{CellKey, MAX_INDEX};

/// Largest scan count and removal counter a restored filter may have: far
/// beyond any real map (2^62), and far enough from `u64::MAX` that going on
/// adding scans cannot overflow.
pub const MAX_COUNTER: u64 = 1 << 62;

impl MapFilter {
    /// Every per-cell record, sorted by key (the filter's internal state; a
    /// record may outlive its cell until the next periodic check).
    pub fn cell_records(&self) -> Vec<(CellKey, CellInfo)> {
        let mut out: Vec<(CellKey, CellInfo)> = self.table.iter().map(|(&k, &c)| (k, c)).collect();
        out.sort_unstable_by_key(|(k, _)| *k);
        out
    }

    /// A filter holding exactly this state, as returned by
    /// [`MapFilter::options`], [`MapFilter::cell_records`],
    /// [`MapFilter::scans`] and [`MapFilter::removal_counts`].
    ///
    /// Errors on invalid options, a counter beyond [`MAX_COUNTER`], and a
    /// record that no run of the filter produces: an index beyond
    /// ±[`MAX_INDEX`], a key given twice, scan numbers outside
    /// `1 ≤ first_seen ≤ last_seen ≤ scans`, no observation, or more
    /// small-cluster observations than observations.
    pub fn from_state(
        options: MapperOptions,
        records: &[(CellKey, CellInfo)],
        scans: u64,
        counts: RemovalCounts,
    ) -> Result<Self> {
        options.validate()?;
        let counters = std::iter::once(("scans", scans)).chain(counts.entries());
        for (name, value) in counters {
            if value > MAX_COUNTER {
                return Err(NdtError::InvalidCounter {
                    name,
                    value,
                    limit: MAX_COUNTER,
                });
            }
        }
        let mut table = CellTable::default();
        table.reserve(records.len());
        for (index, (key, info)) in records.iter().enumerate() {
            let bad = |reason| Err(NdtError::InvalidRecord { index, reason });
            if key.ix.abs() >= MAX_INDEX || key.iy.abs() >= MAX_INDEX {
                return bad("has an index beyond +-2**30");
            }
            if info.first_seen == 0 {
                return bad("was first seen in scan 0 (scans count from 1)");
            }
            if info.first_seen > info.last_seen {
                return bad("was last seen before it was first seen");
            }
            if info.last_seen > scans {
                return bad("was seen in a scan after the last scan");
            }
            if info.observations == 0 {
                return bad("has no observation");
            }
            if info.small_observations > info.observations {
                return bad("has more small-cluster observations than observations");
            }
            if table.insert(*key, *info).is_some() {
                return bad("repeats the index of an earlier record");
            }
        }
        Ok(Self {
            options,
            table,
            scans,
            counts,
            stale: super::StaleRecords::default(),
        })
    }
}
