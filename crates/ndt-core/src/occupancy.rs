//! Which fine cells hold points, kept exact under every insert and removal:
//! a bit per cell ([`CellMask`]), and, once a probe has asked, a bit per
//! block of 4 × 4 cells that holds any. The second answers, for the §V beam
//! walks ([`crate::filter::raywalk::walk_cells_in_skipping`]), "may a cell
//! of this block hold points?" on blocks of 32 × 32 cells (one of its
//! words), 16 × 16 (a quarter of one), 8 × 8 (2 × 2 of its bits) and 4 × 4
//! (one bit), all four from one look-up ([`OccupancyProbe::empty_block`]),
//! and without the pyramid's coarser levels, so it holds while those wait to
//! be brought up to date (a deferral, `NdtGrid::deferral`). A grid that is
//! never walked (the odometry loop's matching grid) never builds it. With
//! the 32 × 32 and 8 × 8 blocks added to the other two, the odometry
//! helper's instructions fell by 7 % (benches/SPEED_LOG.md, session 24).

use std::sync::OnceLock;

use crate::cellmask::{
    pair_bits, quarter_bits, quarter_mask, CellMask, CellMaskReader, BLOCK_BITS as WORD_BITS,
};
use crate::directmemo::DirectMemo;
use crate::key::CellKey;

/// log2 of the side \[cells\] of the blocks with a bit each: a quarter of
/// a word of the cells' mask (so a block empties when that quarter does).
const SMALL_BITS: i32 = WORD_BITS - 1;

/// The block of 4 × 4 cells holding `key`, as a key of that lattice.
#[inline]
fn small_block(key: CellKey) -> CellKey {
    CellKey {
        ix: key.ix >> SMALL_BITS,
        iy: key.iy >> SMALL_BITS,
    }
}

/// The occupied fine cells of a grid (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct Occupancy {
    cells: CellMask,
    /// The occupied blocks of 4 × 4 cells, built at the first
    /// [`Occupancy::probe`] and kept up to date from then on.
    blocks: OnceLock<CellMask>,
}

/// The same cells (the blocks follow from them).
impl PartialEq for Occupancy {
    fn eq(&self, other: &Self) -> bool {
        self.cells == other.cells
    }
}

/// The occupied blocks of 4 × 4 cells of the cells `cells`: each word of
/// `cells` (8 × 8 cells) gives the bits of its occupied quarters.
fn blocks_of(cells: &CellMask) -> CellMask {
    let mut blocks = CellMask::default();
    blocks.set_pairs(cells.words().flat_map(|((bx, by), word)| {
        [(0, 0), (1, 0), (0, 1), (1, 1)]
            .into_iter()
            .filter(move |&(qx, qy)| word & quarter_mask(qx, qy) != 0)
            .map(move |(qx, qy)| {
                let key = CellKey {
                    ix: bx * 2 + qx,
                    iy: by * 2 + qy,
                };
                (key, true)
            })
    }));
    blocks
}

impl Occupancy {
    /// The occupancy of exactly the cells `keys`.
    pub fn of(keys: impl IntoIterator<Item = CellKey>) -> Self {
        Self {
            cells: CellMask::of(keys),
            blocks: OnceLock::new(),
        }
    }

    /// The cells `keys` now hold points.
    pub fn insert(&mut self, keys: &[CellKey]) {
        self.cells.set_all(keys, true);
        if let Some(blocks) = self.blocks.get_mut() {
            blocks.set_pairs(keys.iter().map(|&k| (small_block(k), true)));
        }
    }

    /// The cells `keys` hold no points any more; a block loses its bit
    /// with its last cell (its 4 × 4 cells are a quarter of one word of the
    /// cells' mask).
    pub fn remove(&mut self, keys: &[CellKey]) {
        self.cells.set_all(keys, false);
        let Some(blocks) = self.blocks.get_mut() else {
            return;
        };
        let mut cells = self.cells.reader();
        blocks.set_pairs(
            keys.iter()
                .filter(|&&k| !cells.any_in_quarter(k))
                .map(|&k| (small_block(k), false)),
        );
    }

    /// One bit per occupied cell.
    pub fn cells(&self) -> &CellMask {
        &self.cells
    }

    /// An [`OccupancyProbe`] of these cells.
    pub fn probe(&self) -> OccupancyProbe<'_> {
        OccupancyProbe {
            blocks: self
                .blocks
                .get_or_init(|| blocks_of(&self.cells))
                .window_reader(),
        }
    }

    /// Heap bytes of both masks (an estimate, see [`CellMask::heap_bytes`]).
    pub fn heap_bytes(&self) -> usize {
        self.cells.heap_bytes() + self.blocks.get().map_or(0, CellMask::heap_bytes)
    }
}

/// Answers "may fine cell `key` hold points?" on blocks of 16 × 16 and of
/// 4 × 4 fine cells ([`Occupancy::probe`]): `false` only when no cell of the
/// block holds points. Remembers the last word it read of each 32 × 32
/// window of words ([`CellMask::window_reader`]: 20 × 20 m of 2 cm cells),
/// so the walks of one scan, which all start at the sensor, look up most
/// words once ([`crate::filter::walkmap`]).
#[derive(Debug)]
pub struct OccupancyProbe<'a> {
    blocks: CellMaskReader<'a, DirectMemo>,
}

impl OccupancyProbe<'_> {
    /// log2 of the side \[fine cells\] of the blocks
    /// [`OccupancyProbe::may_hold`] answers for as a whole (16 × 16).
    pub fn block_bits(&self) -> Option<u32> {
        Some((SMALL_BITS + WORD_BITS - 1) as u32)
    }

    /// log2 of the side \[fine cells\] of the smaller blocks
    /// [`OccupancyProbe::may_hold_inner`] answers for (4 × 4).
    pub fn inner_bits(&self) -> Option<u32> {
        Some(SMALL_BITS as u32)
    }

    /// `false` only when no fine cell of `key`'s 16 × 16 block holds points.
    #[inline]
    pub fn may_hold(&mut self, key: CellKey) -> bool {
        self.blocks.any_in_quarter(small_block(key))
    }

    /// `false` only when no fine cell of `key`'s 4 × 4 block holds points.
    #[inline]
    pub fn may_hold_inner(&mut self, key: CellKey) -> bool {
        self.blocks.contains(small_block(key))
    }

    /// log2 of the side \[fine cells\] of the largest aligned block of 32 ×
    /// 32, 16 × 16, 8 × 8 or 4 × 4 fine cells holding `key` that holds no
    /// points (5, 4, 3 or 2); `None` when even the 4 × 4 block holds points.
    /// The four are one word of the blocks' mask, a quarter of it, 2 × 2 of
    /// its bits and one bit: one look-up answers them all (the §V walks ask
    /// this at every step, [`crate::filter::raywalk::walk_cells_in_skipping`]).
    #[inline]
    pub fn empty_block(&mut self, key: CellKey) -> Option<u32> {
        let small = small_block(key);
        let (word, bit) = self.blocks.word_and_bit(small);
        // Largest first; each part's bits only when the larger one holds points.
        let b = if word == 0 {
            SMALL_BITS + WORD_BITS
        } else if word & quarter_bits(small) == 0 {
            SMALL_BITS + WORD_BITS - 1
        } else if word & pair_bits(small) == 0 {
            SMALL_BITS + 1
        } else if word >> bit & 1 == 0 {
            SMALL_BITS
        } else {
            return None;
        };
        Some(b as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};
    use rustc_hash::FxHashSet;

    /// The blocks' bits equal those of the cells present, under random
    /// inserts and removals (including repeated and absent keys).
    #[test]
    fn blocks_follow_the_cells_under_inserts_and_removals() {
        let mut rng = StdRng::seed_from_u64(3);
        let mut occ = Occupancy::default();
        // The blocks are kept from the first probe on.
        let _ = occ.probe();
        let mut cells: FxHashSet<CellKey> = FxHashSet::default();
        for round in 0..400 {
            let keys: Vec<CellKey> = (0..rng.random_range(1..40))
                .map(|_| CellKey {
                    ix: rng.random_range(-40..40),
                    iy: rng.random_range(-40..40),
                })
                .collect();
            if round % 3 == 2 {
                occ.remove(&keys);
                for k in &keys {
                    cells.remove(k);
                }
            } else {
                occ.insert(&keys);
                cells.extend(keys.iter().copied());
            }
            let fresh = Occupancy::of(cells.iter().copied());
            assert_eq!(occ, fresh, "round {round}");
            // Kept and built from the cells, the blocks are the same.
            let _ = fresh.probe();
            assert_eq!(occ.blocks.get(), fresh.blocks.get(), "round {round}");
        }
        let mut probe = occ.probe();
        for ix in -50..50 {
            for iy in -50..50 {
                let key = CellKey { ix, iy };
                let near = |bits: i32| {
                    cells
                        .iter()
                        .any(|c| c.ix >> bits == ix >> bits && c.iy >> bits == iy >> bits)
                };
                assert_eq!(probe.may_hold(key), near(4), "{key:?}");
                assert_eq!(probe.may_hold_inner(key), near(2), "{key:?}");
                // The largest empty block, of 32 down to 4 cells a side,
                // from one word.
                let want = [5, 4, 3, 2]
                    .into_iter()
                    .find(|&b| !near(b))
                    .map(|b| b as u32);
                assert_eq!(probe.empty_block(key), want, "{key:?}");
            }
        }
    }
}
