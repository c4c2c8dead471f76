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

use crate::directmemo::DirectMemo;
use crate::key::CellKey;
use crate::parity::ParityMemo;

/// log2 of a block's side \[cells\] (a block is one word).
pub const BLOCK_BITS: i32 = 3;
const MASK: i32 = (1 << BLOCK_BITS) - 1;

/// The bits of a block's word for one of its quarters (squares of
/// `2^(BLOCK_BITS − 1)` cells a side): `qx`, `qy` 0 for the lower half of
/// the block's columns or rows, 1 for the upper.
pub const fn quarter_mask(qx: i32, qy: i32) -> u64 {
    const HALF: i32 = 1 << (BLOCK_BITS - 1);
    // HALF rows of HALF bits at the block's origin.
    let row = (1u64 << HALF) - 1;
    let mut m = 0;
    let mut r = 0;
    while r < HALF {
        m |= row << (r << BLOCK_BITS);
        r += 1;
    }
    m << (((qy * HALF) << BLOCK_BITS) | (qx * HALF))
}

/// The quarters' bits by `qx + 2 qy` ([`quarter_mask`]).
const QUARTERS: [u64; 4] = [
    quarter_mask(0, 0),
    quarter_mask(1, 0),
    quarter_mask(0, 1),
    quarter_mask(1, 1),
];

/// The bits of the word of `key`'s block for the quarter holding `key`.
#[inline]
pub fn quarter_bits(key: CellKey) -> u64 {
    let half_x = (key.ix & MASK) >> (BLOCK_BITS - 1);
    let half_y = (key.iy & MASK) >> (BLOCK_BITS - 1);
    QUARTERS[(half_x | (half_y << 1)) as usize]
}

/// The bits of the word of `key`'s block for the aligned 2 × 2 cells
/// holding `key` (two bits in each of two rows, `2^BLOCK_BITS` bits apart).
#[inline]
pub fn pair_bits(key: CellKey) -> u64 {
    const ROWS: u64 = 0b11 | 0b11 << (1 << BLOCK_BITS);
    ROWS << ((key.ix & MASK & !1) | ((key.iy & MASK & !1) << BLOCK_BITS))
}

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
        self.set_pairs(keys.iter().map(|&k| (k, member(k))));
    }

    /// Puts each key of `pairs` in the set (`true`) or takes it out, in
    /// order: one look-up per run of keys in one block.
    pub fn set_pairs(&mut self, pairs: impl IntoIterator<Item = (CellKey, bool)>) {
        // The current block with the bits to set and to clear in it.
        let mut run: Option<((i32, i32), u64, u64)> = None;
        for (key, member) in pairs {
            let (block, bit) = split(key);
            let (set, clear) = if member { (1 << bit, 0) } else { (0, 1 << bit) };
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

    /// Every block with a member: its index (cell index `>> BLOCK_BITS`)
    /// and its word (bit `(iy mod 8) · 8 + (ix mod 8)`), in no particular
    /// order.
    pub fn words(&self) -> impl Iterator<Item = ((i32, i32), u64)> + '_ {
        self.blocks.iter().map(|(&b, &w)| (b, w))
    }

    /// A reader that remembers the last block it used of each parity.
    pub fn reader(&self) -> CellMaskReader<'_> {
        CellMaskReader {
            mask: self,
            last: LastWords(ParityMemo::new(0)),
        }
    }

    /// A reader that remembers the last block it used of each 32 × 32
    /// window of blocks, for many reads that fan out from one place (see
    /// [`crate::directmemo`]); it costs 16 KiB to set up.
    pub fn window_reader(&self) -> CellMaskReader<'_, DirectMemo> {
        CellMaskReader {
            mask: self,
            last: DirectMemo::default(),
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

/// The words a [`CellMaskReader`] remembers, by block index ([`LastWords`],
/// [`DirectMemo`]).
pub trait WordMemo {
    /// The word remembered for `block`, if any.
    fn get(&self, block: (i32, i32)) -> Option<u64>;
    /// Remembers `word` for `block` (perhaps in place of another).
    fn set(&mut self, block: (i32, i32), word: u64);
}

/// The last word read of each parity of the block index
/// ([`CellMask::reader`]).
#[derive(Debug, Clone)]
pub struct LastWords(ParityMemo<u64>);

impl WordMemo for LastWords {
    #[inline(always)]
    fn get(&self, block: (i32, i32)) -> Option<u64> {
        self.0.get(block)
    }
    #[inline(always)]
    fn set(&mut self, block: (i32, i32), word: u64) {
        self.0.set(block, word);
    }
}

/// Reads a [`CellMask`] remembering words it read ([`LastWords`] by
/// default: a cell's neighbourhood, and a run of cells along a beam, mostly
/// lie in one block, and any 2 × 2 blocks have one of each parity).
#[derive(Debug)]
pub struct CellMaskReader<'a, M = LastWords> {
    mask: &'a CellMask,
    last: M,
}

impl<M: WordMemo> CellMaskReader<'_, M> {
    /// The word of `block` (0 when the mask has none).
    #[inline(always)]
    fn word(&mut self, block: (i32, i32)) -> u64 {
        match self.last.get(block) {
            Some(w) => w,
            None => self.find(block),
        }
    }

    /// The hashed look-up of a word not remembered.
    #[inline(never)]
    fn find(&mut self, block: (i32, i32)) -> u64 {
        let w = self.mask.blocks.get(&block).copied().unwrap_or(0);
        self.last.set(block, w);
        w
    }

    /// Whether the set has a member in the quarter of a block (a square of
    /// `2^(BLOCK_BITS − 1)` cells a side, aligned as the blocks) holding
    /// `key`: the quarter's rows of the block's word.
    #[inline]
    pub fn any_in_quarter(&mut self, key: CellKey) -> bool {
        self.word(split(key).0) & quarter_bits(key) != 0
    }

    /// The word of the block holding `key` (0 when the set has none of its
    /// cells) and `key`'s bit in it.
    #[inline]
    pub fn word_and_bit(&mut self, key: CellKey) -> (u64, u32) {
        let (block, bit) = split(key);
        (self.word(block), bit)
    }

    /// `true` when `key` is in the set.
    #[inline]
    pub fn contains(&mut self, key: CellKey) -> bool {
        let (word, bit) = self.word_and_bit(key);
        word >> bit & 1 == 1
    }

    /// The members of the 3 × 3 block of cells around `key` as 9 bits, bit
    /// `3 · (dy + 1) + (dx + 1)` for the cell at offset `(dx, dy)`. The
    /// block lies in 1, 2 or 4 words, each read once; a row is three bits of
    /// its word, or of the 16 bits of its two words side by side where it
    /// crosses a block border.
    #[inline]
    pub fn block3(&mut self, key: CellKey) -> u16 {
        let (x0, y0) = (key.ix - 1, key.iy - 1);
        let (left, right) = (x0 >> BLOCK_BITS, (x0 + 2) >> BLOCK_BITS);
        let (low, high) = (y0 >> BLOCK_BITS, (y0 + 2) >> BLOCK_BITS);
        let mut pair = |by: i32| {
            let w = self.word((left, by));
            (
                w,
                if right == left {
                    w
                } else {
                    self.word((right, by))
                },
            )
        };
        let below = pair(low);
        let above = if high == low { below } else { pair(high) };
        let shift = x0 & MASK;
        let mut bits = 0u16;
        for r in 0..3 {
            let y = y0 + r;
            let (wl, wr) = if y >> BLOCK_BITS == low { below } else { above };
            let row = (y & MASK) << BLOCK_BITS;
            let both = (wl >> row & 0xff) | (wr >> row & 0xff) << 8;
            bits |= ((both >> shift & 0b111) as u16) << (3 * r);
        }
        bits
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
        let mut blocks = mask.reader();
        let minority = |key: CellKey| cells.get(&key).is_some_and(|s| s.count < MIN_POINTS);
        for iy in -22..22 {
            for ix in -22..22 {
                let key = CellKey { ix, iy };
                assert_eq!(reader.contains(key), minority(key), "{key:?}");
                let bits = blocks.block3(key);
                for i in 0..9 {
                    let n = key.offset((i % 3) - 1, (i / 3) - 1);
                    assert_eq!(bits >> i & 1 == 1, minority(n), "{key:?} {i}");
                }
            }
        }
    }
}
