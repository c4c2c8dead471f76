//! The last tile (or block) index met of each parity, with what it maps to.
//!
//! The cell stores ([`crate::table`], [`crate::cellmask`], the update's key
//! set) group cells in square tiles found through a hash map. Their
//! look-ups come in runs along a scan's surfaces and around a cell's 8
//! neighbours (§IV-A), which stay within a 2 × 2 block of tiles; any 2 × 2
//! tile indices have one of each parity `(x mod 2, y mod 2)`, so remembering
//! the last index of each parity answers most look-ups with one compare
//! instead of a hash.

/// Which of the 4 remembered entries a tile (or block) index uses: its
/// parity `(x mod 2) + 2 (y mod 2)`. Any 2 × 2 indices have one of each.
#[inline(always)]
pub(crate) fn parity(index: (i32, i32)) -> usize {
    ((index.0 & 1) | ((index.1 & 1) << 1)) as usize & 3
}

/// A tile index packed into one word (one compare).
#[inline(always)]
pub(crate) fn packed(index: (i32, i32)) -> u64 {
    (u64::from(index.0 as u32) << 32) | u64::from(index.1 as u32)
}

/// No tile index packs to this: |index| ≤ 2²⁷ for keys within
/// [`crate::key::MAX_INDEX`], never `i32::MIN`.
pub(crate) const NEVER: u64 = 0x8000_0000_8000_0000;

/// Per parity: the packed index remembered ([`NEVER`]: none) and its value.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ParityMemo<V> {
    keys: [u64; 4],
    values: [V; 4],
}

impl<V: Copy> ParityMemo<V> {
    /// Nothing remembered (`fill` stands in the unused values).
    pub(crate) const fn new(fill: V) -> Self {
        Self {
            keys: [NEVER; 4],
            values: [fill; 4],
        }
    }

    /// The value remembered for `index`, if it is the last of its parity.
    #[inline(always)]
    pub(crate) fn get(&self, index: (i32, i32)) -> Option<V> {
        let p = parity(index);
        (self.keys[p] == packed(index)).then(|| self.values[p])
    }

    /// Remembers `value` for `index` (in place of the last of its parity).
    #[inline(always)]
    pub(crate) fn set(&mut self, index: (i32, i32), value: V) {
        let p = parity(index);
        self.keys[p] = packed(index);
        self.values[p] = value;
    }

    /// Forgets `index`, if remembered.
    #[inline]
    pub(crate) fn forget(&mut self, index: (i32, i32)) {
        let p = parity(index);
        if self.keys[p] == packed(index) {
            self.keys[p] = NEVER;
        }
    }

    /// Forgets everything.
    #[inline]
    pub(crate) fn clear(&mut self) {
        self.keys = [NEVER; 4];
    }
}

/// Nothing remembered.
impl<V: Copy + Default> Default for ParityMemo<V> {
    fn default() -> Self {
        Self::new(V::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remembers_the_last_index_of_each_parity() {
        let mut memo = ParityMemo::new(0u32);
        for (i, index) in [(0, 0), (1, 0), (0, 1), (-1, -1)].into_iter().enumerate() {
            memo.set(index, i as u32 + 1);
        }
        assert_eq!(memo.get((0, 0)), Some(1));
        assert_eq!(memo.get((-1, -1)), Some(4));
        // Same parity as (0, 0): replaces it.
        memo.set((2, -2), 9);
        assert_eq!((memo.get((0, 0)), memo.get((2, -2))), (None, Some(9)));
        memo.forget((1, 1));
        assert_eq!(memo.get((-1, -1)), Some(4), "another index of that parity");
        memo.forget((-1, -1));
        assert_eq!(memo.get((-1, -1)), None);
        memo.clear();
        assert_eq!(memo.get((1, 0)), None);
        // The extremes of the index range pack apart from "none".
        let lim = crate::key::MAX_INDEX >> 3;
        memo.set((-lim, lim), 7);
        assert_eq!(memo.get((-lim, lim)), Some(7));
        assert_eq!(memo.get((lim, -lim)), None);
    }
}
