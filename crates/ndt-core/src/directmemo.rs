//! The last word met of each index modulo 32 on both axes: a direct-mapped
//! table of 32 × 32 entries, which remembers every index of any 32 × 32
//! window of them at once.
//!
//! The §V walks of one scan ([`crate::filter::walkmap`]) all start at the
//! sensor and fan out: the words of the occupancy probe they read lie
//! within a few metres of it, and a 32 × 32 window of words of 32 × 32 cells
//! covers 20 × 20 m on a 2 cm grid. Kept across a scan's beams, this table
//! answers most of their reads after the first beams with one compare,
//! where [`crate::cellmask::LastWords`]'s four entries answered only the
//! reads within the last few words.

use crate::cellmask::WordMemo;
use crate::parity::{packed, NEVER};

/// log2 of the table's side \[indices\].
const SIDE_BITS: i32 = 5;
const SIDE_MASK: i32 = (1 << SIDE_BITS) - 1;

/// Which entry an index uses: its coordinates modulo 32.
#[inline(always)]
fn slot(index: (i32, i32)) -> usize {
    ((index.0 & SIDE_MASK) | ((index.1 & SIDE_MASK) << SIDE_BITS)) as usize
}

/// Per slot: the packed index remembered (none at first) and its word
/// (16 KiB in all).
#[derive(Debug, Clone)]
pub struct DirectMemo {
    entries: Box<[(u64, u64)]>,
}

/// Nothing remembered.
impl Default for DirectMemo {
    fn default() -> Self {
        Self {
            entries: vec![(NEVER, 0); 1 << (2 * SIDE_BITS)].into_boxed_slice(),
        }
    }
}

impl WordMemo for DirectMemo {
    /// The word remembered for `index`, if it is the last of its slot.
    #[inline(always)]
    fn get(&self, index: (i32, i32)) -> Option<u64> {
        let (key, word) = self.entries[slot(index)];
        (key == packed(index)).then_some(word)
    }

    /// Remembers `word` for `index` (in place of the last of its slot).
    #[inline(always)]
    fn set(&mut self, index: (i32, i32), word: u64) {
        self.entries[slot(index)] = (packed(index), word);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remembers_a_window_of_32_by_32_indices() {
        let mut memo = DirectMemo::default();
        let value = |x: i32, y: i32| (x * 1000 + y) as u64;
        for x in -40..-8 {
            for y in 7..39 {
                memo.set((x, y), value(x, y));
            }
        }
        for x in -40..-8 {
            for y in 7..39 {
                assert_eq!(memo.get((x, y)), Some(value(x, y)));
            }
        }
        // An index 32 apart takes the same slot.
        assert_eq!(memo.get((-8, 7)), None);
        memo.set((-8, 7), 5);
        assert_eq!((memo.get((-8, 7)), memo.get((-40, 7))), (Some(5), None));
        // The extremes of the index range pack apart from "none".
        let lim = crate::key::MAX_INDEX >> 3;
        memo.set((-lim, lim), 7);
        assert_eq!(memo.get((-lim, lim)), Some(7));
        assert_eq!(memo.get((lim, -lim)), None);
    }
}
