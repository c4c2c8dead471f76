//! A flat directory of a [`crate::table::CellTable`]'s tiles: one word per
//! tile index of a rectangle holding every tile, so a tile is found by one
//! indexed load, with no hash and no branch on which tile was met last
//! (a branch a scan's irregular crossings of tile borders made the
//! processor mispredict about one time in four).
//!
//! The rectangle grows (by doubling, so a map growing by scans is laid out
//! again a logarithmic number of times) to take every new tile. A sparse
//! table over a large area would make it large: while the rectangle holds
//! more than 16 words a tile (64 bytes, a quarter of a tile's slots) and
//! more than 16 Ki words in all (64 KiB), the directory is off and the
//! table finds its tiles by hash; it is laid out again once enough tiles
//! fill the rectangle.

/// No tile at this index (out of the tiles' range).
pub const NONE: u32 = u32::MAX;

/// Words of the rectangle a table may use per tile it holds.
const SPARSE: usize = 16;
/// Words of the rectangle always allowed (64 KiB).
const SMALL: usize = 1 << 14;

/// See the module docs.
#[derive(Debug, Clone)]
pub struct TileDirectory {
    /// The rectangle's lowest tile index.
    x0: i32,
    y0: i32,
    /// Its size in tiles (0 × 0: no tile yet).
    w: u32,
    h: u32,
    /// Row by row, the tile of each index or [`NONE`]; empty while the
    /// directory is off.
    words: Vec<u32>,
    /// The answer outside the rectangle: `Some(NONE)` while on, `None` off.
    /// (Off is also "no words, a rectangle": kept as the answer itself, so
    /// a look-up outside costs no test of it.)
    outside: Option<u32>,
}

impl Default for TileDirectory {
    fn default() -> Self {
        Self {
            x0: 0,
            y0: 0,
            w: 0,
            h: 0,
            words: Vec::new(),
            outside: Some(NONE),
        }
    }
}

impl TileDirectory {
    /// The tile at `index`: `Some(NONE)` where the table has none, `None`
    /// when the directory is off (ask the hash).
    #[inline(always)]
    pub fn get(&self, index: (i32, i32)) -> Option<u32> {
        // Off, no word is kept: inside the rectangle too, `None`. The hot
        // path keeps its own test rather than `position`'s: 0.3 % fewer
        // instructions in `insert_case` (benches/SPEED_LOG.md, session 44).
        let (dx, dy) = self.offset(index);
        if dx < self.w && dy < self.h {
            self.words
                .get(dy as usize * self.w as usize + dx as usize)
                .copied()
        } else {
            self.outside
        }
    }

    /// Records tile `t` at `index` (`NONE`: no tile there any more);
    /// `tiles` is the number of tiles the table then holds, and `all` gives
    /// every `(index, tile)` of it, for a new layout.
    pub fn set(
        &mut self,
        index: (i32, i32),
        t: u32,
        tiles: usize,
        all: impl Iterator<Item = ((i32, i32), u32)>,
    ) {
        if let Some(i) = self.word(index) {
            if let Some(w) = self.words.get_mut(i) {
                *w = t;
            }
            return;
        }
        // Off, or outside: nothing to forget.
        if t == NONE {
            return;
        }
        if !self.contains(index) {
            self.grow(index);
        }
        // A new rectangle, or a new tile while off: laid out anew when dense
        // enough.
        // In u64: a rectangle across the whole key range has 2⁵⁶ words.
        let size = u64::from(self.w) * u64::from(self.h);
        let allowed = SMALL.max(SPARSE.saturating_mul(tiles)) as u64;
        if size <= allowed {
            self.lay_out(all);
        } else {
            self.words = Vec::new();
            self.outside = None;
        }
    }

    /// `index` from the rectangle's lowest corner (below it: wrapped to
    /// beyond any side).
    #[inline(always)]
    fn offset(&self, index: (i32, i32)) -> (u32, u32) {
        (
            index.0.wrapping_sub(self.x0) as u32,
            index.1.wrapping_sub(self.y0) as u32,
        )
    }

    /// Where `index` lies in the rectangle, row by row; `None` outside it.
    #[inline(always)]
    fn position(&self, index: (i32, i32)) -> Option<usize> {
        let (dx, dy) = self.offset(index);
        (dx < self.w && dy < self.h).then(|| dy as usize * self.w as usize + dx as usize)
    }

    /// Whether `index` lies in the rectangle.
    fn contains(&self, index: (i32, i32)) -> bool {
        self.position(index).is_some()
    }

    /// The word of `index` while on and inside.
    fn word(&self, index: (i32, i32)) -> Option<usize> {
        self.position(index).filter(|&i| i < self.words.len())
    }

    /// Grows the rectangle to hold `index`, doubling each side that must
    /// grow (at least), so a map growing scan by scan lays it out again a
    /// logarithmic number of times.
    fn grow(&mut self, index: (i32, i32)) {
        if self.w == 0 {
            // A first tile: 8 × 8 around it.
            (self.x0, self.y0, self.w, self.h) = (index.0 - 4, index.1 - 4, 8, 8);
            return;
        }
        let span = |lo: i32, n: u32, at: i32| -> (i32, u32) {
            let (mut lo, mut hi, at, n) = (
                i64::from(lo),
                i64::from(lo) + i64::from(n),
                i64::from(at),
                i64::from(n),
            );
            if at < lo {
                lo = at.min(lo - n);
            } else if at >= hi {
                hi = (at + 1).max(hi + n);
            }
            (lo as i32, (hi - lo) as u32)
        };
        (self.x0, self.w) = span(self.x0, self.w, index.0);
        (self.y0, self.h) = span(self.y0, self.h, index.1);
    }

    /// The words of the rectangle from every `(index, tile)` (on).
    fn lay_out(&mut self, all: impl Iterator<Item = ((i32, i32), u32)>) {
        self.words.clear();
        self.words.resize(self.w as usize * self.h as usize, NONE);
        self.outside = Some(NONE);
        for (index, t) in all {
            if let Some(i) = self.word(index) {
                if let Some(w) = self.words.get_mut(i) {
                    *w = t;
                }
            }
        }
    }

    /// Whether the directory answers (else the table asks its hash).
    #[cfg(test)]
    pub fn is_on(&self) -> bool {
        self.outside.is_some()
    }

    /// Empty again (and on).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Bytes on the heap.
    pub fn heap_bytes(&self) -> usize {
        self.words.capacity() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// The directory against a hash map of the same tiles: it answers
    /// every index while on (growing to the left, right, up and down), goes
    /// off when a far tile would make it too sparse, and on again once
    /// enough tiles fill its rectangle.
    /// Sets tile `t` at `index` in both.
    fn add(
        dir: &mut TileDirectory,
        naive: &mut HashMap<(i32, i32), u32>,
        index: (i32, i32),
        t: u32,
    ) {
        if t == NONE {
            naive.remove(&index);
        } else {
            naive.insert(index, t);
        }
        dir.set(index, t, naive.len(), naive.iter().map(|(&i, &t)| (i, t)));
    }

    /// The directory answers as `naive` over a window, and for every tile.
    fn check(dir: &TileDirectory, naive: &HashMap<(i32, i32), u32>) {
        for x in -40..40 {
            for y in -40..40 {
                let want = naive.get(&(x, y)).copied().unwrap_or(NONE);
                assert_eq!(dir.get((x, y)), Some(want), "({x}, {y})");
            }
        }
        for (&i, &t) in naive {
            assert_eq!(dir.get(i), Some(t), "{i:?}");
        }
    }

    /// The directory against a hash map of the same tiles: it answers
    /// every index while on (growing to the left, right, up and down), goes
    /// off when a far tile would make it too sparse, and on again once
    /// enough tiles fill its rectangle.
    #[test]
    fn answers_as_a_hash_map_and_goes_off_and_on_with_the_density() {
        let mut dir = TileDirectory::default();
        let mut naive = HashMap::new();
        let near = [
            (0, 0),
            (5, 0),
            (-7, 1),
            (2, 9),
            (3, -12),
            (30, 30),
            (-35, -35),
        ];
        for (t, index) in (0..).zip(near) {
            add(&mut dir, &mut naive, index, t);
            assert!(dir.is_on());
            check(&dir, &naive);
        }
        // A tile removed, and its number taken by a new one elsewhere.
        add(&mut dir, &mut naive, (5, 0), NONE);
        check(&dir, &naive);
        add(&mut dir, &mut naive, (6, 1), 1);
        check(&dir, &naive);
        // Far away: the rectangle would hold more than `SMALL` words for 8
        // tiles, so the directory is off and answers nothing.
        let far = (2_000, 0);
        add(&mut dir, &mut naive, far, 100);
        assert!(!dir.is_on());
        assert_eq!(
            (dir.get((0, 0)), dir.get(far), dir.heap_bytes()),
            (None, None, 0)
        );
        // Removals while off change nothing.
        add(&mut dir, &mut naive, (0, 0), NONE);
        assert!(!dir.is_on());
        // Filled column by column between the two until dense enough: on
        // again, every tile listed.
        let mut t = 200;
        let mut x = 0;
        while !dir.is_on() {
            for y in 0..32 {
                add(&mut dir, &mut naive, (x, y), t);
                t += 1;
            }
            x += 1;
            assert!(x < 2_000, "never on again");
        }
        check(&dir, &naive);
        dir.clear();
        assert!(dir.is_on() && dir.get((0, 0)) == Some(NONE) && dir.heap_bytes() == 0);
    }

    /// Tiles at the two ends of the key range (|cell index| < 2³⁰, so tile
    /// indices within ±2²⁷): the rectangle spans them without overflow and
    /// stays off; the hash answers.
    #[test]
    fn tiles_at_the_ends_of_the_key_range_leave_it_off() {
        let mut dir = TileDirectory::default();
        let mut naive = HashMap::new();
        let end = (crate::key::MAX_INDEX >> 3) - 1;
        for (t, index) in (0..).zip([(0, 0), (end, end), (-end, -end), (-end, end)]) {
            add(&mut dir, &mut naive, index, t);
        }
        assert!(!dir.is_on());
        assert_eq!(
            (dir.get((end, end)), dir.get((0, 1)), dir.heap_bytes()),
            (None, None, 0)
        );
    }
}
