//! Which cells of a pyramid level hold fewer than [`MIN_POINTS`] points: the
//! minority cells of §IV-A(3), whose fused distributions take in the sums of
//! their 8 neighbours.
//!
//! When a cell's sums change, every minority cell around it must be
//! recomputed. Asking the level's hash map about each of the 8 neighbours of
//! every changed cell costs a cache miss each; this mask answers from one bit
//! per cell, 8 × 8 cells to a 64-bit word, so a cell's neighbourhood mostly
//! lies in one word that a small, cache-resident map finds.

use rustc_hash::FxHashMap;

use crate::cell::{CellStats, MIN_POINTS};
use crate::key::CellKey;

/// log2 of a block's side \[cells\].
const BLOCK_BITS: i32 = 3;
const MASK: i32 = (1 << BLOCK_BITS) - 1;

/// One bit per cell, set when the cell exists with fewer than
/// [`MIN_POINTS`] points.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MinorityMask {
    blocks: FxHashMap<(i32, i32), u64>,
}

#[inline]
fn split(key: CellKey) -> ((i32, i32), u32) {
    let block = (key.ix >> BLOCK_BITS, key.iy >> BLOCK_BITS);
    let bit = ((key.iy & MASK) << BLOCK_BITS) | (key.ix & MASK);
    (block, bit as u32)
}

impl MinorityMask {
    /// The mask of every cell of `cells`.
    pub fn of<'a>(cells: impl IntoIterator<Item = (CellKey, &'a CellStats)>) -> Self {
        let mut mask = Self::default();
        for (key, stats) in cells {
            mask.set(key, Some(stats));
        }
        mask
    }

    /// Records the sums of `key` now (`None`: the cell is gone).
    pub fn set(&mut self, key: CellKey, stats: Option<&CellStats>) {
        let (block, bit) = split(key);
        if stats.is_some_and(|s| s.count < MIN_POINTS) {
            *self.blocks.entry(block).or_insert(0) |= 1 << bit;
        } else if let Some(word) = self.blocks.get_mut(&block) {
            *word &= !(1 << bit);
            if *word == 0 {
                self.blocks.remove(&block);
            }
        }
    }

    /// A reader that remembers the last block it used.
    pub fn reader(&self) -> MinorityReader<'_> {
        MinorityReader {
            mask: self,
            last: None,
        }
    }

    /// Heap bytes of the mask (an estimate, see
    /// [`crate::table::hash_map_bytes`]).
    pub fn heap_bytes(&self) -> usize {
        crate::table::hash_map_bytes(
            self.blocks.capacity(),
            std::mem::size_of::<((i32, i32), u64)>(),
        )
    }
}

/// Reads a [`MinorityMask`] remembering the last block (a cell's
/// neighbourhood mostly lies in one).
#[derive(Debug)]
pub struct MinorityReader<'a> {
    mask: &'a MinorityMask,
    last: Option<((i32, i32), u64)>,
}

impl MinorityReader<'_> {
    /// `true` when `key` is a minority cell.
    #[inline]
    pub fn contains(&mut self, key: CellKey) -> bool {
        let (block, bit) = split(key);
        let word = match self.last {
            Some((b, w)) if b == block => w,
            _ => {
                let w = self.mask.blocks.get(&block).copied().unwrap_or(0);
                self.last = Some((block, w));
                w
            }
        };
        word >> bit & 1 == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    #[test]
    fn agrees_with_the_counts_under_random_changes() {
        let mut rng = StdRng::seed_from_u64(5);
        let mut cells: FxHashMap<CellKey, CellStats> = FxHashMap::default();
        let mut mask = MinorityMask::default();
        for _ in 0..20_000 {
            let key = CellKey {
                ix: rng.random_range(-20..20),
                iy: rng.random_range(-20..20),
            };
            if rng.random_range(0..4) == 0 {
                cells.remove(&key);
            } else {
                cells.entry(key).or_default().count += rng.random_range(1..3);
            }
            mask.set(key, cells.get(&key));
        }
        let rebuilt = MinorityMask::of(cells.iter().map(|(k, s)| (*k, s)));
        assert_eq!(rebuilt, mask);
        let mut reader = mask.reader();
        for iy in -22..22 {
            for ix in -22..22 {
                let key = CellKey { ix, iy };
                let want = cells.get(&key).is_some_and(|s| s.count < MIN_POINTS);
                assert_eq!(reader.contains(key), want, "{key:?}");
            }
        }
    }
}
