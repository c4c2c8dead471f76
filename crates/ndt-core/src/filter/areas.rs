//! §V-B: the two areas of a scan, and step b-1.
//!
//! For a 2 cm object the URG-04LX is reliable only within 0.5 m of the sensor
//! (the paper's preliminary experiments; the catalogue's 1.2 m is too
//! optimistic): **Area 1** is within the reliable range, **Area 2** beyond.
//! Step b-1 deletes the cells of small objects that were never observed from
//! Area 1.

use crate::filter::observation::CellTable;
use crate::key::CellKey;

/// Where a measurement lies relative to the reliable range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Area {
    /// Area 1: within the reliable range ("reliable").
    Reliable,
    /// Area 2: beyond it ("suspicious").
    Suspicious,
}

impl Area {
    /// The area of a point at `range` \[m\] from the sensor, with Area 1 up to
    /// and including `reliable_range` \[m\] (the paper: 0.5 m).
    pub fn of(range: f64, reliable_range: f64) -> Area {
        if range <= reliable_range {
            Area::Reliable
        } else {
            Area::Suspicious
        }
    }
}

/// §V step b-1: the small-object cells (see
/// [`crate::filter::observation::CellInfo::is_small`]) that were never
/// observed from Area 1. Sorted, so results are deterministic.
pub fn unconfirmed_small(table: &CellTable) -> Vec<CellKey> {
    super::sorted_keys(table.iter().map(|(&k, c)| (k, c)), |_, c| {
        c.is_small() && !c.seen_in_area1
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::filter::observation::CellInfo;

    #[test]
    fn areas_split_at_the_reliable_range() {
        assert_eq!(Area::of(0.49, 0.5), Area::Reliable);
        assert_eq!(Area::of(0.5, 0.5), Area::Reliable);
        assert_eq!(Area::of(0.51, 0.5), Area::Suspicious);
    }

    #[test]
    fn b1_selects_small_cells_never_seen_in_area1() {
        let mut table = CellTable::default();
        let k = |i| CellKey { ix: i, iy: 1 };
        // 0: small, Area 2 only. 1: small, once from Area 1. 2: big, Area 2.
        table
            .entry(k(0))
            .or_insert(CellInfo::new(1))
            .observe(1, true, false);
        let c1 = table.entry(k(1)).or_insert(CellInfo::new(1));
        c1.observe(1, true, false);
        c1.observe(2, true, true);
        table
            .entry(k(2))
            .or_insert(CellInfo::new(1))
            .observe(1, false, false);
        assert_eq!(unconfirmed_small(&table), vec![k(0)]);
    }
}
