//! A sparse table of per-cell values stored in dense tiles: the look-up
//! structure of the matcher's distributions (§III-B keeps cells sparse; the
//! matcher looks a cell up for every point of every iteration) and of the
//! pyramid's sums (an insert re-sums each changed coarse cell from its 4
//! children, which always share a tile).
//!
//! Cells are grouped into square tiles of [`TILE`] × [`TILE`] cells. A flat
//! directory over a rectangle holding every tile finds a tile by its index
//! with one indexed load ([`crate::tiledir`]); a table too sparse for it
//! (its cells spread over a large area) finds its tiles in a hash map.
//! Inside a tile a cell is a direct array access to the slot of its value
//! in one contiguous `Vec`. Consecutive points of a scan mostly fall into
//! the same tile, so [`Cursor`] remembers the last tiles and skips the
//! directory for them, and the 8 neighbours of the neighbour search
//! (§IV-A(1)) are mostly in that tile too.

use rustc_hash::FxHashMap;

use crate::key::CellKey;
use crate::parity::ParityMemo;
use crate::spare::clone_vec;
use crate::tiledir::{TileDirectory, NONE};

/// log2 of the tile side \[cells\].
const TILE_BITS: i32 = 3;
/// Tile side \[cells\]: 8 × 8 cells (16 cm tiles on a 2 cm grid).
pub const TILE: i32 = 1 << TILE_BITS;
const MASK: i32 = TILE - 1;
/// No value in this slot.
const EMPTY: u32 = u32::MAX;

/// The 8 offsets `(dx, dy)` of the ring at Chebyshev distance 1 in the order
/// the §IV-A(1) neighbour search takes them ([`crate::neighbor`]): that
/// order breaks ties between equally near means.
pub const RING1: [(i32, i32); 8] = [
    (-1, -1),
    (-1, 1),
    (0, -1),
    (0, 1),
    (1, -1),
    (1, 1),
    (-1, 0),
    (1, 0),
];

type Tile = [u32; (TILE * TILE) as usize];

/// Tile index and slot within the tile of `key`.
#[inline]
fn split(key: CellKey) -> ((i32, i32), usize) {
    let tile = (key.ix >> TILE_BITS, key.iy >> TILE_BITS);
    let slot = ((key.iy & MASK) * TILE + (key.ix & MASK)) as usize;
    (tile, slot)
}

/// Heap bytes of a hash map with `capacity` entries of `entry` bytes, as
/// hashbrown lays it out: a power-of-two number of buckets at most 7/8 full,
/// each with its entry and one control byte, plus one group of control
/// bytes. An estimate (the allocator's own overhead is not counted).
pub fn hash_map_bytes(capacity: usize, entry: usize) -> usize {
    if capacity == 0 {
        return 0;
    }
    let buckets = if capacity < 8 {
        (capacity + 1).next_power_of_two()
    } else {
        (capacity * 8 / 7).next_power_of_two()
    };
    buckets * (entry + 1) + 16
}

/// Values of type `T` keyed by [`CellKey`], in tiles (see the module docs).
#[derive(Debug)]
pub struct CellTable<T> {
    tiles: FxHashMap<(i32, i32), u32>,
    slots: Vec<Tile>,
    /// Occupied tile slots per tile, so empty tiles can be reused.
    used: Vec<u32>,
    free_tiles: Vec<u32>,
    /// The values, contiguous, and beside them (same index) their keys. A
    /// value type that should start on a cache line says so by its own
    /// alignment (the matcher's distributions do).
    values: Vec<T>,
    keys: Vec<CellKey>,
    /// The tile of the last insert of each parity of the tile index, so runs
    /// of inserts in one tile, and inserts around one cell across tile
    /// borders, skip the hash (with the directory off).
    inserted: ParityMemo<u32>,
    /// The tiles by index without a hash, while the table is dense enough.
    dir: TileDirectory,
}

/// A copy with the original's spare capacity: inserts into a clone grow
/// its vectors as they would the original's (amortised), instead of the
/// first insert after cloning reallocating and copying every value.
impl<T: Clone> Clone for CellTable<T> {
    fn clone(&self) -> Self {
        Self {
            tiles: self.tiles.clone(),
            slots: clone_vec(&self.slots),
            used: clone_vec(&self.used),
            free_tiles: clone_vec(&self.free_tiles),
            values: clone_vec(&self.values),
            keys: clone_vec(&self.keys),
            inserted: self.inserted,
            dir: self.dir.clone(),
        }
    }
}

/// Equal when both hold the same keys with equal values (whatever the order
/// they were inserted in).
impl<T: PartialEq> PartialEq for CellTable<T> {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().all(|(k, v)| other.get(k) == Some(v))
    }
}

impl<T> FromIterator<(CellKey, T)> for CellTable<T> {
    fn from_iter<I: IntoIterator<Item = (CellKey, T)>>(iter: I) -> Self {
        let mut table = Self::default();
        for (key, value) in iter {
            table.insert(key, value);
        }
        table
    }
}

impl<T> Default for CellTable<T> {
    fn default() -> Self {
        Self {
            tiles: FxHashMap::default(),
            slots: Vec::new(),
            used: Vec::new(),
            free_tiles: Vec::new(),
            values: Vec::new(),
            keys: Vec::new(),
            inserted: ParityMemo::new(NONE),
            dir: TileDirectory::default(),
        }
    }
}

impl<T> CellTable<T> {
    /// An empty table with room for about `cells` values.
    pub fn with_capacity(cells: usize) -> Self {
        let mut t = Self::default();
        t.values.reserve(cells);
        t.keys.reserve(cells);
        t
    }

    /// Number of values the table holds without reallocating.
    pub fn capacity(&self) -> usize {
        self.values.capacity()
    }

    /// Number of cells with a value.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// `true` when no cell has a value.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The value of `key`, if any.
    #[inline]
    pub fn get(&self, key: CellKey) -> Option<&T> {
        let (tile, slot) = split(key);
        self.value_at(self.find_tile(tile), slot)
    }

    /// The tile of index `tile` ([`NONE`] where the table has none): from
    /// the directory inline, from the hash out of line (the directory off),
    /// so the common path inlines into the matcher's loop.
    #[inline(always)]
    fn find_tile(&self, tile: (i32, i32)) -> u32 {
        match self.dir.get(tile) {
            Some(t) => t,
            None => self.hashed_tile(tile),
        }
    }

    /// [`CellTable::find_tile`] with the directory off.
    #[inline(never)]
    fn hashed_tile(&self, tile: (i32, i32)) -> u32 {
        self.tiles.get(&tile).copied().unwrap_or(NONE)
    }

    #[inline]
    fn value_at(&self, tile: u32, slot: usize) -> Option<&T> {
        let i = *self.slots.get(tile as usize)?.get(slot)?;
        if i == EMPTY {
            None
        } else {
            Some(&self.values[i as usize])
        }
    }

    /// `true` when `key` has a value.
    #[inline]
    pub fn contains(&self, key: CellKey) -> bool {
        self.get(key).is_some()
    }

    /// The value of `key`, set to `T::default()` first when it has none (one
    /// look-up; runs of calls in one tile skip the hash, as inserts do).
    #[inline]
    pub fn get_or_default(&mut self, key: CellKey) -> &mut T
    where
        T: Default,
    {
        self.index_or_default(key).1
    }

    /// Sets the value at index `index` of the values (as
    /// [`Cursor::index`] gave it, with no removal since: see
    /// [`CellTable::value`]): no look-up. An index out of range changes
    /// nothing.
    #[inline]
    pub fn set_at(&mut self, index: u32, value: T) {
        if let Some(v) = self.values.get_mut(index as usize) {
            *v = value;
        }
    }

    /// The value at index `index` of the values (as [`Cursor::index`] or
    /// [`CellTable::index_or_default`] gave it: a new key's value is pushed,
    /// so only a removal moves an index); `None` out of range. No look-up.
    #[inline]
    pub fn value(&self, index: u32) -> Option<&T> {
        self.values.get(index as usize)
    }

    /// The key of the value at index `index` (see [`CellTable::value`]).
    #[inline]
    pub fn key(&self, index: u32) -> Option<CellKey> {
        self.keys.get(index as usize).copied()
    }

    /// The index of `key`'s value among the values (see [`Cursor::index`])
    /// and the value, set to `T::default()` first when it has none (one
    /// look-up, as [`CellTable::get_or_default`]).
    #[inline]
    pub fn index_or_default(&mut self, key: CellKey) -> (u32, &mut T)
    where
        T: Default,
    {
        let (t, slot) = self.tile_of(key);
        let i = match self.slots[t as usize][slot] {
            EMPTY => {
                self.push(t, slot, key, T::default());
                self.values.len() - 1
            }
            i => i as usize,
        };
        (i as u32, &mut self.values[i])
    }

    /// Removes every value (keeping the capacity).
    pub fn clear(&mut self) {
        self.tiles.clear();
        self.slots.clear();
        self.used.clear();
        self.free_tiles.clear();
        self.values.clear();
        self.keys.clear();
        self.inserted.clear();
        self.dir.clear();
    }

    /// Sets the value of `key` (replacing any). Unlike
    /// [`CellTable::replace`], the value it replaces is not read: on a table
    /// larger than the processor's caches that read is a miss the write
    /// would otherwise wait for.
    ///
    /// Inline: a shaped update writes each touched cell's mean with it (about
    /// 650 calls an insert), and the call cost more than the write
    /// (benches/SPEED_LOG.md, session 43).
    #[inline(always)]
    pub fn insert(&mut self, key: CellKey, value: T) {
        let (t, slot) = self.tile_of(key);
        match self.slots[t as usize][slot] {
            EMPTY => self.push(t, slot, key, value),
            i => self.values[i as usize] = value,
        }
    }

    /// Sets the value of `key`, returning the one it replaces (one look-up
    /// for both).
    pub fn replace(&mut self, key: CellKey, value: T) -> Option<T> {
        let (t, slot) = self.tile_of(key);
        match self.slots[t as usize][slot] {
            EMPTY => {
                self.push(t, slot, key, value);
                None
            }
            i => Some(std::mem::replace(&mut self.values[i as usize], value)),
        }
    }

    /// The tile of `key` (a new one when it has none) and its slot there:
    /// through the directory inline (which, on, lists every tile: one it
    /// does not have is new), any other way out of line.
    #[inline(always)]
    fn tile_of(&mut self, key: CellKey) -> (u32, usize) {
        let (tile, slot) = split(key);
        match self.dir.get(tile) {
            Some(NONE) => (self.new_tile(tile), slot),
            Some(t) => (t, slot),
            None => (self.tile_by_hash(tile), slot),
        }
    }

    /// [`CellTable::tile_of`] with the directory off: the last inserted
    /// tile of its parity, else through the hash, else a new tile.
    #[inline(never)]
    fn tile_by_hash(&mut self, tile: (i32, i32)) -> u32 {
        if let Some(t) = self.inserted.get(tile) {
            return t;
        }
        let t = match self.tiles.get(&tile).copied() {
            Some(t) => t,
            None => self.new_tile(tile),
        };
        self.inserted.set(tile, t);
        t
    }

    /// A tile for index `tile`, which has none (an emptied tile's storage
    /// if there is one), entered in the hash and the directory.
    #[inline(never)]
    fn new_tile(&mut self, tile: (i32, i32)) -> u32 {
        let t = match self.free_tiles.pop() {
            Some(t) => t,
            None => {
                self.slots.push([EMPTY; (TILE * TILE) as usize]);
                self.used.push(0);
                (self.slots.len() - 1) as u32
            }
        };
        self.tiles.insert(tile, t);
        let all = self.tiles.iter().map(|(&i, &t)| (i, t));
        self.dir.set(tile, t, self.tiles.len(), all);
        t
    }

    /// Stores `value` for `key` in the empty `slot` of tile `t`.
    fn push(&mut self, t: u32, slot: usize, key: CellKey, value: T) {
        self.slots[t as usize][slot] = self.values.len() as u32;
        self.values.push(value);
        self.keys.push(key);
        self.used[t as usize] += 1;
    }

    /// Removes the value of `key`, if any, and returns it.
    pub fn remove(&mut self, key: CellKey) -> Option<T> {
        let (tile, slot) = split(key);
        let t = *self.tiles.get(&tile)?;
        let i = self.slots[t as usize][slot];
        if i == EMPTY {
            return None;
        }
        self.slots[t as usize][slot] = EMPTY;
        self.used[t as usize] -= 1;
        if self.used[t as usize] == 0 {
            self.tiles.remove(&tile);
            self.inserted.forget(tile);
            self.dir
                .set(tile, NONE, self.tiles.len(), std::iter::empty());
            self.free_tiles.push(t);
        }
        // Keep the values contiguous: move the last one into the hole.
        let value = self.values.swap_remove(i as usize);
        self.keys.swap_remove(i as usize);
        if let Some(&moved) = self.keys.get(i as usize) {
            let (mt, ms) = split(moved);
            if let Some(&mt) = self.tiles.get(&mt) {
                self.slots[mt as usize][ms] = i;
            }
        }
        Some(value)
    }

    /// Every `(key, value)`, in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = (CellKey, &T)> {
        self.keys.iter().zip(&self.values).map(|(k, v)| (*k, v))
    }

    /// Every key with a value, in no particular order (that of
    /// [`CellTable::iter`]).
    pub fn keys(&self) -> impl Iterator<Item = CellKey> + '_ {
        self.keys.iter().copied()
    }

    /// Bytes this table holds on the heap (capacity, not length): the values,
    /// the tiles and the tile index.
    pub fn heap_bytes(&self) -> usize {
        self.values.capacity() * std::mem::size_of::<T>()
            + self.keys.capacity() * std::mem::size_of::<CellKey>()
            + self.slots.capacity() * std::mem::size_of::<Tile>()
            + self.used.capacity() * 4
            + self.free_tiles.capacity() * 4
            + self.dir.heap_bytes()
            + hash_map_bytes(
                self.tiles.capacity(),
                std::mem::size_of::<((i32, i32), u32)>(),
            )
    }

    /// Whether the tiles are found through the directory (else by hash).
    #[cfg(test)]
    fn directory_on(&self) -> bool {
        self.dir.is_on()
    }

    /// A reader that remembers the last tiles it used (see [`Cursor`]).
    #[inline]
    pub fn cursor(&self) -> Cursor<'_, T> {
        Cursor {
            table: self,
            tiles: ParityMemo::new(NONE),
        }
    }

    /// A reader that finds every tile through the directory (while it is
    /// on), remembering none: for look-ups that cross tile borders too
    /// irregularly for the remembered tiles to be predicted (a changed
    /// level's parents, in [`crate::pyramid`]).
    #[inline]
    pub fn direct_cursor(&self) -> Cursor<'_, T, false> {
        Cursor {
            table: self,
            tiles: ParityMemo::new(NONE),
        }
    }
}

/// Reads a [`CellTable`] remembering the last tile looked up of each parity
/// of its index (`tx mod 2`, `ty mod 2`), so runs of look-ups in one tile
/// (a scan's consecutive points) find it once, and so do the look-ups of a
/// cell's neighbours (§IV-A) across tile borders: any 2 × 2 block of tiles
/// has one tile of each parity. A tile not remembered comes from the
/// table's directory, or its hash map when the directory is off. (In the
/// matcher's loop the remembered tile is nearly always the one; a
/// directory read first would cost it instructions and no time.) With
/// `REMEMBER` false ([`CellTable::direct_cursor`]) the directory is read
/// first.
#[derive(Debug)]
pub struct Cursor<'a, T, const REMEMBER: bool = true> {
    table: &'a CellTable<T>,
    /// Per parity: the tile remembered ([`NONE`]: the table has none there).
    tiles: ParityMemo<u32>,
}

impl<'a, T, const REMEMBER: bool> Cursor<'a, T, REMEMBER> {
    /// The value of `key`, if any (as [`CellTable::get`]).
    #[inline(always)]
    pub fn get(&mut self, key: CellKey) -> Option<&'a T> {
        let i = self.index(key)?;
        self.table.values.get(i as usize)
    }

    /// The tile of index `tile` ([`NONE`] where the table has none), through
    /// the remembered tiles, else the directory, else the hash.
    #[inline(always)]
    fn tile_index(&mut self, tile: (i32, i32)) -> u32 {
        if !REMEMBER {
            if let Some(t) = self.table.dir.get(tile) {
                return t;
            }
        }
        match self.tiles.get(tile) {
            Some(t) => t,
            None => {
                let t = self.table.find_tile(tile);
                self.tiles.set(tile, t);
                t
            }
        }
    }

    /// The slots of tile `tile`, if it has any (through the remembered
    /// tiles, as [`Cursor::get`]).
    #[inline(always)]
    fn tile_slots(&mut self, tile: (i32, i32)) -> Option<&'a Tile> {
        let t = self.tile_index(tile);
        self.table.slots.get(t as usize)
    }

    /// The value at index `i` of the values (a slot's content), or `none`
    /// for an empty slot ([`EMPTY`], out of the values' range): a select,
    /// not a branch, on the irregular pattern of occupied cells.
    #[inline(always)]
    fn value_or<'b>(&self, i: u32, none: &'b T) -> &'b T
    where
        'a: 'b,
    {
        let values = &self.table.values;
        let i = i as usize;
        match values.get(i.min(values.len().saturating_sub(1))) {
            Some(v) => std::hint::select_unpredictable(i < values.len(), v, none),
            None => none,
        }
    }

    /// The value in slot `slot` of `tile`, or `none` (see
    /// [`Cursor::value_or`]).
    #[inline(always)]
    fn in_tile<'b>(&self, tile: &Tile, slot: usize, none: &'b T) -> &'b T
    where
        'a: 'b,
    {
        self.value_or(tile.get(slot).copied().unwrap_or(EMPTY), none)
    }

    /// The values of the 3 × 3 block of cells around `key`, row by row
    /// (`iy − 1` first, `ix − 1` first in a row), `none` for a cell without
    /// one: the neighbourhood of §IV-A(3). The block lies in at most 2 × 2
    /// tiles (one of each parity: remembered together), whose slots are
    /// read directly; one branch only, on whether it lies in one tile.
    #[inline]
    pub fn block3<'b>(&mut self, key: CellKey, none: &'b T) -> [&'b T; 9]
    where
        'a: 'b,
    {
        const NO_TILE: Tile = [EMPTY; (TILE * TILE) as usize];
        // Inside its tile (36 of a tile's 64 cells), the block is 3 runs of 3
        // slots of that one tile: one tile look-up, fixed offsets. On the
        // Intel log's loop this takes the block from 313 to 250 instructions
        // (benches/SPEED_LOG.md, session 13).
        let (sx, sy) = (key.ix & MASK, key.iy & MASK);
        if sx > 0 && sy > 0 && sx < MASK && sy < MASK {
            let (tile, slot) = split(key);
            let slots = self.tile_slots(tile).unwrap_or(&NO_TILE);
            let (row, first) = (TILE as usize, slot.wrapping_sub(TILE as usize + 1));
            return std::array::from_fn(|i| {
                self.in_tile(slots, first.wrapping_add((i / 3) * row + i % 3), none)
            });
        }
        let (x0, y0) = (key.ix - 1, key.iy - 1);
        let (tx0, ty0) = (x0 >> TILE_BITS, y0 >> TILE_BITS);
        let (tx1, ty1) = ((x0 + 2) >> TILE_BITS, (y0 + 2) >> TILE_BITS);
        let tiles = [(tx0, ty0), (tx1, ty0), (tx0, ty1), (tx1, ty1)]
            .map(|t| self.tile_slots(t).unwrap_or(&NO_TILE));
        // Per column and per row: which tile (bit 0: right, bit 1: above)
        // and the slot's part within it.
        let cols: [(usize, i32); 3] = std::array::from_fn(|c| {
            (
                usize::from((x0 + c as i32) >> TILE_BITS != tx0),
                (x0 + c as i32) & MASK,
            )
        });
        let rows: [(usize, i32); 3] = std::array::from_fn(|r| {
            (
                usize::from((y0 + r as i32) >> TILE_BITS != ty0) << 1,
                ((y0 + r as i32) & MASK) * TILE,
            )
        });
        let mut out = [none; 9];
        for (i, o) in out.iter_mut().enumerate() {
            let ((tc, sc), (tr, sr)) = (cols[i % 3], rows[i / 3]);
            let slot = tiles[(tc | tr) & 3][((sr + sc) & (TILE * TILE - 1)) as usize];
            *o = self.value_or(slot, none);
        }
        out
    }

    /// Calls `f` with the value of each of the 8 cells around `key` that
    /// has one (the ring at Chebyshev distance 1 of the §IV-A(1) neighbour
    /// search), in the order of [`RING1`]. Inside its tile (36 of a tile's
    /// 64 cells) the ring is read from that tile's slots at fixed offsets,
    /// with one tile look-up; else cell by cell (reading the 2 × 2 tiles at
    /// once as [`Cursor::block3`] does cost more there).
    #[inline(always)]
    pub fn for_ring1(&mut self, key: CellKey, mut f: impl FnMut(&'a T)) {
        let (sx, sy) = (key.ix & MASK, key.iy & MASK);
        if sx > 0 && sy > 0 && sx < MASK && sy < MASK {
            let (tile, slot) = split(key);
            let Some(slots) = self.tile_slots(tile) else {
                return;
            };
            let values = &self.table.values;
            for (dx, dy) in RING1 {
                let s = slot.wrapping_add_signed((dy * TILE + dx) as isize);
                // An empty slot (`EMPTY`) is out of the values' range.
                if let Some(v) = slots.get(s).and_then(|&i| values.get(i as usize)) {
                    f(v);
                }
            }
            return;
        }
        for (dx, dy) in RING1 {
            if let Some(v) = self.get(key.offset(dx, dy)) {
                f(v);
            }
        }
    }

    /// The values of the 4 cells of this level under cell `parent` of the
    /// level above (keys `2 · parent + (0|1, 0|1)`), in the order (0, 0),
    /// (1, 0), (0, 1), (1, 1), `none` for a cell without one. The 4 always
    /// share a tile.
    #[inline]
    pub fn quad<'b>(&mut self, parent: CellKey, none: &'b T) -> [&'b T; 4]
    where
        'a: 'b,
    {
        let first = CellKey {
            ix: parent.ix * 2,
            iy: parent.iy * 2,
        };
        let (tile, slot) = split(first);
        let Some(slots) = self.tile_slots(tile) else {
            return [none; 4];
        };
        let row = TILE as usize;
        [
            self.in_tile(slots, slot, none),
            self.in_tile(slots, slot + 1, none),
            self.in_tile(slots, slot + row, none),
            self.in_tile(slots, slot + row + 1, none),
        ]
    }

    /// The index of `key`'s value among the table's values (stable until
    /// the next removal: a new key's value is pushed), if it has one.
    #[inline(always)]
    pub fn index(&mut self, key: CellKey) -> Option<u32> {
        let (tile, slot) = split(key);
        let slots = self.tile_slots(tile)?;
        match slots.get(slot).copied() {
            None | Some(EMPTY) => None,
            Some(i) => Some(i),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// A tile emptied by removals is freed and its storage reused by the
    /// next new tile; inserts into the first tile again must not write
    /// through a remembered tile number (a tile of either parity).
    #[test]
    fn emptied_tiles_are_forgotten_by_inserts() {
        for (a, b) in [((0, 0), (16, 0)), ((9, 1), (1, 17)), ((-8, -8), (-24, 8))] {
            let (ka, kb) = (CellKey { ix: a.0, iy: a.1 }, CellKey { ix: b.0, iy: b.1 });
            let mut table = CellTable::default();
            table.insert(ka, 1);
            assert_eq!(table.remove(ka), Some(1));
            table.insert(kb, 2);
            table.insert(ka, 3);
            assert_eq!((table.get(ka), table.get(kb)), (Some(&3), Some(&2)));
            *table.get_or_default(ka) += 1;
            assert_eq!(table.replace(kb, 5), Some(2));
            assert_eq!(
                (table.get(ka), table.get(kb), table.len()),
                (Some(&4), Some(&5), 2)
            );
        }
    }

    /// Every read of `table` around `center` (±10 cells: single cells, a
    /// cursor, blocks and quads) as `naive` holds it.
    fn assert_reads_as(table: &CellTable<i32>, naive: &HashMap<CellKey, i32>, center: CellKey) {
        assert_cursor_reads_as(table, table.cursor(), naive, center);
        assert_cursor_reads_as(table, table.direct_cursor(), naive, center);
    }

    /// [`assert_reads_as`] with one cursor (remembering tiles or not).
    fn assert_cursor_reads_as<const R: bool>(
        table: &CellTable<i32>,
        mut cursor: Cursor<'_, i32, R>,
        naive: &HashMap<CellKey, i32>,
        center: CellKey,
    ) {
        for dx in -10..10 {
            for dy in -10..10 {
                let key = center.offset(dx, dy);
                let want = naive.get(&key);
                assert_eq!((table.get(key), cursor.get(key)), (want, want), "{key:?}");
                let index = cursor.index(key).and_then(|i| table.value(i));
                assert_eq!(index, want, "{key:?}");
                assert_block_and_quad(&mut cursor, naive, key);
            }
        }
    }

    /// The 3 × 3 block around `key` and the 4 cells under it (as the level
    /// below's parent) read as `naive` holds them (-1: no value).
    fn assert_block_and_quad<const R: bool>(
        cursor: &mut Cursor<'_, i32, R>,
        naive: &HashMap<CellKey, i32>,
        key: CellKey,
    ) {
        let none = -1;
        let block = cursor.block3(key, &none);
        for (i, got) in block.iter().enumerate() {
            let n = key.offset((i % 3) as i32 - 1, (i / 3) as i32 - 1);
            assert_eq!(**got, *naive.get(&n).unwrap_or(&none), "{key:?} {i}");
        }
        let quad = cursor.quad(key, &none);
        for (i, got) in quad.iter().enumerate() {
            let child = CellKey {
                ix: 2 * key.ix + (i % 2) as i32,
                iy: 2 * key.iy + (i / 2) as i32,
            };
            assert_eq!(**got, *naive.get(&child).unwrap_or(&none), "{key:?} {i}");
        }
    }

    /// Two clusters of cells far apart make the table too sparse for its
    /// directory: its tiles are then found by hash, with the same reads and
    /// writes; filled in between, it takes the directory again.
    #[test]
    fn a_table_too_sparse_for_its_directory_reads_the_same() {
        let mut table = CellTable::default();
        let mut naive = HashMap::new();
        let (near, far) = (CellKey { ix: 0, iy: 0 }, CellKey { ix: 40_000, iy: 0 });
        let mut x: u64 = 3;
        let mut step = 0;
        let mut churn =
            |table: &mut CellTable<i32>, naive: &mut HashMap<CellKey, i32>, c: CellKey| {
                for _ in 0..2_000 {
                    x = x
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let key = c.offset(((x >> 33) % 17) as i32 - 8, ((x >> 13) % 17) as i32 - 8);
                    step += 1;
                    if (x >> 60) < 5 {
                        assert_eq!(table.remove(key), naive.remove(&key));
                    } else {
                        assert_eq!(table.replace(key, step), naive.insert(key, step));
                    }
                }
            };
        churn(&mut table, &mut naive, near);
        assert!(table.directory_on());
        assert_reads_as(&table, &naive, near);
        churn(&mut table, &mut naive, far);
        assert!(!table.directory_on());
        churn(&mut table, &mut naive, near);
        assert_reads_as(&table, &naive, near);
        assert_reads_as(&table, &naive, far);
        // A cell in every tile from one cluster to the other.
        for ix in (0..40_000).step_by(TILE as usize) {
            let key = CellKey { ix, iy: 24 };
            *table.get_or_default(key) += 1;
            *naive.entry(key).or_insert(0) += 1;
        }
        assert!(table.directory_on());
        churn(&mut table, &mut naive, far);
        for c in [near, far, CellKey { ix: 20_000, iy: 24 }] {
            assert_reads_as(&table, &naive, c);
        }
        assert_eq!(table.len(), naive.len());
    }

    #[test]
    fn matches_a_hash_map_under_inserts_and_removes() {
        let mut table = CellTable::default();
        let mut naive = HashMap::new();
        let mut x: u64 = 7;
        for step in 0..20_000 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let key = CellKey {
                ix: ((x >> 33) % 41) as i32 - 20,
                iy: ((x >> 13) % 37) as i32 - 18,
            };
            if (x >> 60) < 5 {
                assert_eq!(table.remove(key), naive.remove(&key));
            } else if (x >> 60) < 7 {
                // An upsert: adds to the value held, or to 0 when none.
                *table.get_or_default(key) += 1;
                *naive.entry(key).or_insert(0) += 1;
            } else if (x >> 60) < 10 {
                // `replace` gives back what the map held.
                assert_eq!(table.replace(key, step), naive.insert(key, step));
            } else {
                table.insert(key, step);
                naive.insert(key, step);
            }
        }
        assert_eq!(table.len(), naive.len());
        let mut cursor = table.cursor();
        for ix in -22..22 {
            for iy in -20..20 {
                let key = CellKey { ix, iy };
                assert_eq!(table.get(key), naive.get(&key));
                assert_eq!(cursor.get(key), naive.get(&key));
            }
        }
        // Rings, blocks and quads read what single look-ups read, inside
        // tiles, across their borders and where no tile is.
        let mut blocks = table.cursor();
        for ix in -22..22 {
            for iy in -20..20 {
                let key = CellKey { ix, iy };
                let mut ring = Vec::new();
                blocks.for_ring1(key, |v| ring.push(*v));
                let want: Vec<i32> = RING1
                    .iter()
                    .filter_map(|&(dx, dy)| naive.get(&key.offset(dx, dy)).copied())
                    .collect();
                assert_eq!(ring, want, "{key:?}");
                assert_block_and_quad(&mut blocks, &naive, key);
            }
        }
        // Equal to a table of the same entries inserted in another order.
        let mut entries: Vec<_> = naive.iter().map(|(k, v)| (*k, *v)).collect();
        entries.sort_unstable();
        let sorted: CellTable<i32> = entries.iter().rev().copied().collect();
        assert!(sorted == table);
        let mut keys: Vec<_> = table.keys().collect();
        keys.sort_unstable();
        assert_eq!(keys, entries.iter().map(|(k, _)| *k).collect::<Vec<_>>());
        let mut cleared = sorted;
        cleared.clear();
        assert!(cleared.is_empty() && cleared != table);
        assert_eq!(cleared.get(entries[0].0), None);
        *cleared.get_or_default(entries[0].0) += 5;
        assert_eq!(cleared.get(entries[0].0), Some(&5));
        let mut all: Vec<_> = table.iter().map(|(k, v)| (k, *v)).collect();
        all.sort_unstable();
        let mut want: Vec<_> = naive.into_iter().collect();
        want.sort_unstable();
        assert_eq!(all, want);
    }
}
