//! A set of cells as one bit per cell, 8 × 8 cells to a 64-bit word.
//!
//! Two questions are asked of many cells in a row, where asking the level's
//! hash map of sums costs a cache miss each: is this neighbour a minority
//! cell of §IV-A(3) (fewer than [`crate::cell::MIN_POINTS`] points, so its
//! fused distribution takes in the changed cell's sums)? and does this cell
//! on a beam's path hold points at all (§V step d walks)? A cell's
//! neighbourhood, and a run of cells along a beam, mostly lie in one word,
//! which a small, cache-resident map finds.

use rustc_hash::FxHashMap;

use crate::key::CellKey;

/// log2 of a block's side \[cells\].
const BLOCK_BITS: i32 = 3;
const MASK: i32 = (1 << BLOCK_BITS) - 1;

/// One bit per cell of a set of cells.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CellMask {
    blocks: FxHashMap<(i32, i32), u64>,
}

#[inline]
fn split(key: CellKey) -> ((i32, i32), u32) {
    let block = (key.ix >> BLOCK_BITS, key.iy >> BLOCK_BITS);
    let bit = ((key.iy & MASK) << BLOCK_BITS) | (key.ix & MASK);
    (block, bit as u32)
}

impl CellMask {
    /// The mask of the cells `keys`.
    pub fn of(keys: impl IntoIterator<Item = CellKey>) -> Self {
        let mut mask = Self::default();
        for key in keys {
            mask.set(key, true);
        }
        mask
    }

    /// Puts every key of `keys` in the set (`true`) or takes them out: one
    /// look-up per run of keys in one block (a scan's cells come in runs
    /// along its surfaces), otherwise as [`CellMask::set`] key by key.
    pub fn set_all(&mut self, keys: &[CellKey], member: bool) {
        self.set_each(keys, |_| member);
    }

    /// Puts each key of `keys` in the set or takes it out as `member` says:
    /// one look-up per run of keys in one block.
    pub fn set_each(&mut self, keys: &[CellKey], mut member: impl FnMut(CellKey) -> bool) {
        // The current block with the bits to set and to clear in it.
        let mut run: Option<((i32, i32), u64, u64)> = None;
        for &key in keys {
            let (block, bit) = split(key);
            let (set, clear) = if member(key) {
                (1 << bit, 0)
            } else {
                (0, 1 << bit)
            };
            match &mut run {
                Some((b, s, c)) if *b == block => {
                    *s |= set;
                    *c |= clear;
                }
                _ => {
                    if let Some((b, s, c)) = run.take() {
                        self.update(b, s, c);
                    }
                    run = Some((block, set, clear));
                }
            }
        }
        if let Some((b, s, c)) = run {
            self.update(b, s, c);
        }
    }

    /// Sets the bits `set` and clears the bits `clear` of `block` (disjoint).
    fn update(&mut self, block: (i32, i32), set: u64, clear: u64) {
        if set != 0 {
            let word = self.blocks.entry(block).or_insert(0);
            *word = (*word | set) & !clear;
        } else if let Some(word) = self.blocks.get_mut(&block) {
            *word &= !clear;
            if *word == 0 {
                self.blocks.remove(&block);
            }
        }
    }

    /// Puts `key` in the set (`true`) or takes it out.
    pub fn set(&mut self, key: CellKey, member: bool) {
        self.set_all(&[key], member);
    }

    /// A reader that remembers the last block it used.
    pub fn reader(&self) -> CellMaskReader<'_> {
        CellMaskReader {
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

/// Reads a [`CellMask`] remembering the last block (a cell's neighbourhood
/// and a run of cells along a beam mostly lie in one).
#[derive(Debug)]
pub struct CellMaskReader<'a> {
    mask: &'a CellMask,
    last: Option<((i32, i32), u64)>,
}

impl CellMaskReader<'_> {
    /// `true` when `key` is in the set.
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
    use crate::cell::{CellStats, MIN_POINTS};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    #[test]
    fn agrees_with_the_counts_under_random_changes() {
        let mut rng = StdRng::seed_from_u64(5);
        let mut cells: FxHashMap<CellKey, CellStats> = FxHashMap::default();
        let mut mask = CellMask::default();
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
            mask.set(key, cells.get(&key).is_some_and(|s| s.count < MIN_POINTS));
        }
        // The same changes in runs give the same mask.
        let mut runs = CellMask::default();
        let keys: Vec<CellKey> = cells.keys().copied().collect();
        runs.set_all(&keys, true);
        let gone: Vec<CellKey> = keys
            .iter()
            .copied()
            .filter(|k| cells.get(k).is_some_and(|s| s.count >= MIN_POINTS))
            .collect();
        runs.set_all(&gone, false);
        let rebuilt = CellMask::of(
            cells
                .iter()
                .filter(|(_, s)| s.count < MIN_POINTS)
                .map(|(k, _)| *k),
        );
        assert_eq!(rebuilt, mask);
        assert_eq!(runs, mask);
        // One pass in and out by runs gives the same mask.
        let mut each = CellMask::of(keys.iter().copied());
        each.set_each(&keys, |k| {
            cells.get(&k).is_some_and(|s| s.count < MIN_POINTS)
        });
        assert_eq!(each, mask);
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
