//! A set of cell keys that an update uses for its bookkeeping ("seen this
//! key already?") and keeps between calls, so that each call reuses its
//! capacity instead of allocating (and clearing) a fresh hash set. It holds
//! nothing between calls: a clone starts empty (with the same capacity).
//!
//! The keys an update meets come in runs along a scan's surfaces (and the 8
//! neighbours of a cell, §IV-A(3)), so the set keeps one bit per cell in
//! blocks of 16 × 16 cells, found through a hash map of blocks but for the
//! last block of each parity asked about: most questions are a compare and a
//! bit test, not a hashed look-up. (8 × 8 blocks, one word each, hashed
//! twice as often: the Intel loop ran 0.4 % more instructions; benches/SPEED_LOG.md,
//! session 17.)

use rustc_hash::FxHashMap;

use crate::key::CellKey;
use crate::parity::ParityMemo;

/// log2 of a block's side \[cells\].
const BLOCK_BITS: i32 = 4;
const MASK: i32 = (1 << BLOCK_BITS) - 1;
/// Words of a block's bits.
const WORDS: usize = 1 << (2 * BLOCK_BITS - 6);

/// One block's bits, row by row.
type Block = [u64; WORDS];

/// A set of keys, a bit per cell (see the module docs).
#[derive(Debug, Default)]
pub(crate) struct KeySet {
    /// Block index → its position in `words`.
    index: FxHashMap<(i32, i32), u32>,
    words: Vec<Block>,
    /// The last block asked about of each parity of its index (any 2 × 2
    /// blocks, around a cell's neighbours, have one of each), and its
    /// position.
    last: ParityMemo<u32>,
}

impl KeySet {
    /// Adds `key`; `true` when it was not in the set.
    #[inline]
    pub(crate) fn insert(&mut self, key: CellKey) -> bool {
        let block = (key.ix >> BLOCK_BITS, key.iy >> BLOCK_BITS);
        let index = ((key.iy & MASK) << BLOCK_BITS) | (key.ix & MASK);
        let bit = 1u64 << (index & 63);
        let at = match self.last.get(block) {
            Some(at) => at,
            None => self.block(block),
        };
        match self
            .words
            .get_mut(at as usize)
            .and_then(|b| b.get_mut((index >> 6) as usize))
        {
            Some(word) => {
                let fresh = *word & bit == 0;
                *word |= bit;
                fresh
            }
            None => false,
        }
    }

    /// The position of `block`'s word, a new empty one when it has none.
    #[inline(never)]
    fn block(&mut self, block: (i32, i32)) -> u32 {
        let next = self.words.len() as u32;
        let at = *self.index.entry(block).or_insert(next);
        if at == next {
            self.words.push([0; WORDS]);
        }
        self.last.set(block, at);
        at
    }

    /// Empties the set, keeping its capacity.
    pub(crate) fn clear(&mut self) {
        self.index.clear();
        self.words.clear();
        self.last.clear();
    }
}

/// `keys` each once, in the order of their first appearance (`seen`: an
/// empty set, left holding them).
pub(crate) fn first_touch(keys: impl Iterator<Item = CellKey>, seen: &mut KeySet) -> Vec<CellKey> {
    // Room for every key at once, rather than growth by doubling.
    let mut out = Vec::with_capacity(keys.size_hint().1.unwrap_or(0));
    out.extend(keys.filter(|&k| seen.insert(k)));
    out
}

/// A reusable set of keys (see the module docs).
#[derive(Debug, Default)]
pub(crate) struct KeyScratch(KeySet);

impl KeyScratch {
    /// The set, emptied (its capacity kept).
    pub(crate) fn take(&mut self) -> &mut KeySet {
        self.0.clear();
        &mut self.0
    }
}

/// Empty, as the scratch is between calls, with the original's capacity:
/// the first updates of a clone then run as the original's would, instead of
/// growing the set from nothing (a rehash at every doubling).
impl Clone for KeyScratch {
    fn clone(&self) -> Self {
        Self(KeySet {
            index: FxHashMap::with_capacity_and_hasher(self.0.index.capacity(), Default::default()),
            words: Vec::with_capacity(self.0.words.capacity()),
            last: ParityMemo::new(0),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn a_clone_is_empty_with_the_capacity_of_the_original() {
        let mut scratch = KeyScratch::default();
        let set = scratch.take();
        // Each key in a block of its own.
        let apart = (1 << BLOCK_BITS) + 1;
        for i in 0..1000 {
            set.insert(CellKey {
                ix: apart * i,
                iy: -apart * i,
            });
        }
        let mut clone = scratch.clone();
        assert!(clone.0.words.is_empty());
        assert!(
            clone.0.index.capacity() >= 1000,
            "{}",
            clone.0.index.capacity()
        );
        // Taking the original empties it and keeps its capacity.
        let taken = scratch.take();
        assert!(taken.words.is_empty() && taken.words.capacity() >= 1000);
        assert!(taken.insert(CellKey { ix: 0, iy: 0 }));
        assert!(clone.take().index.capacity() >= 1000);
    }

    /// `insert` answers as a hash set does, for keys in runs, scattered, and
    /// on both sides of 0 (blocks by arithmetic shift), across `clear`s.
    #[test]
    fn insert_answers_as_a_hash_set() {
        let mut set = KeySet::default();
        let mut naive = HashSet::new();
        let mut x: u64 = 3;
        for round in 0..4 {
            for step in 0..5000 {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let key = if step % 3 == 0 {
                    CellKey {
                        ix: ((x >> 33) % 200) as i32 - 100,
                        iy: ((x >> 13) % 200) as i32 - 100,
                    }
                } else {
                    // A run: a neighbour of a recent key.
                    CellKey {
                        ix: (step % 17) - 8 + round,
                        iy: ((x >> 40) % 5) as i32 - 2,
                    }
                };
                assert_eq!(set.insert(key), naive.insert(key), "{key:?}");
            }
            set.clear();
            naive.clear();
        }
    }
}
