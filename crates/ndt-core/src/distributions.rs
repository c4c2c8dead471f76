//! The normal distributions the matcher pairs points with, derived from the
//! grid's sums: eq. (7) per cell, expanded by `k` (eq. 8), for cells with
//! fewer than 3 points the fused distribution of §IV-A(3), and for cells
//! finer than the shape scale the covariance of their ancestor
//! ([`crate::shape`]).

use nalgebra::Vector2;
use rustc_hash::FxHashSet;

use crate::cell::{CellStats, Gaussian, MIN_POINTS};
use crate::cellmask::CellMask;
use crate::gather;
use crate::key::CellKey;
use crate::moments::{self, GaussBatch, StatsBatch};
use crate::scratch::{first_touch, KeyScratch, KeySet};
use crate::shape::{AncestorShape, Shape, ShapeMemo, ShapeReader};
use crate::shaped::{Ancestor, ShapedCursor, ShapedStore};
use crate::table::{CellTable, Cursor};

/// What decides a cell's distribution besides its sums.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistOptions {
    /// `k` of eq. (8): both covariance eigenvalues are multiplied by it (≥ 1
    /// widens the basin; 1 is the original NDT).
    pub expansion: f64,
    /// §IV-A(3): a cell with fewer than 3 points takes the distribution of the
    /// summed eq. (6) terms of itself and its 8 neighbours.
    pub fuse_minority: bool,
    /// Smallest standard deviation of a distribution before expansion \[m\]
    /// (see [`crate::cell::DEFAULT_SIGMA_FLOOR`]).
    pub sigma_floor: f64,
    /// Cells finer than this \[m\] take the covariance of their ancestor of
    /// (at least) this size ([`crate::shape`]); 0 = off.
    pub shape_cell: f64,
}

/// The cells of one level a change of the grid touched: their keys and,
/// when the pyramid gave them ([`crate::pyramid::Pyramid::changed_indices`]),
/// the indices of their values among the level's sums, in the same order;
/// with a shape level, the cells that changed there.
#[derive(Debug, Clone, Copy)]
pub struct Changed<'a> {
    /// The cells' keys.
    pub keys: &'a [CellKey],
    /// Per key, the index of its sums' value, if known.
    pub indices: Option<&'a [u32]>,
    /// The changed cells of the shape level (empty without one): the keys'
    /// ancestors there, each once, in the order of their first descendant
    /// among `keys`, as [`crate::pyramid::Pyramid::add`] lists a level's
    /// changes (each parent once, in the order of its first changed child).
    pub ancestors: &'a [CellKey],
}

/// The distribution of every cell that has one, for one [`DistOptions`].
#[derive(Debug, Clone)]
pub struct Distributions {
    options: DistOptions,
    level: usize,
    cell_size: f64,
    /// Levels up to the shape level (0: no shape level applies).
    shape_depth: usize,
    store: Store,
    /// The level's minority cells (with fusion; empty without).
    minority: CellMask,
    /// The keys an update has met (reused between updates).
    seen: KeyScratch,
}

/// A distribution starting on a cache line: a [`Gaussian`] is 64 bytes, so
/// each one takes exactly one line and a look-up touches one line, not two.
#[derive(Debug, Clone, Copy)]
#[repr(align(64))]
struct Line(Gaussian);

/// How the distributions are kept.
#[derive(Debug, Clone)]
enum Store {
    /// Each cell its own (no shape level).
    Own(CellTable<Line>),
    /// Cells under an ancestor with a shape share its covariance part
    /// ([`crate::shaped`]).
    Shaped(ShapedStore),
}

impl Distributions {
    /// Builds the distributions of all cells; `shape`: the ancestors whose
    /// covariance they take (see [`crate::shape`]), if a shape level applies.
    pub fn build(
        cells: &CellTable<CellStats>,
        cell_size: f64,
        level: usize,
        options: DistOptions,
        shape: Option<Shape<'_>>,
    ) -> Self {
        // Room for as many cells as the level's sums have room for, not
        // just for the cells there are: a table built exactly full copies
        // itself whole at the first insert that adds a cell (session 52).
        let room = cells.capacity();
        let store = match shape {
            None => {
                let mut map = CellTable::with_capacity(room);
                let keys: Vec<CellKey> = cells.keys().collect();
                own_distributions(cells, cell_size, options, &keys, |key, g| {
                    if let Some(g) = g {
                        map.insert(key, Line(g));
                    }
                });
                Store::Own(map)
            }
            Some(s) => {
                let mut store = ShapedStore::with_capacity(room);
                // Every ancestor's shape once, then every cell.
                for at in s.cells().keys() {
                    store.set_ancestor(at, shape_of_ancestor(s, at, options));
                }
                let mut private = Vec::new();
                for (key, own) in cells.iter() {
                    let at = crate::pyramid::coarse_key(key, s.depth());
                    if set_cell(&mut store, cell_size, at, key, own) {
                        private.push(key);
                    }
                }
                own_distributions(cells, cell_size, options, &private, |key, g| {
                    store.set_own(key, g);
                });
                Store::Shaped(store)
            }
        };
        // The shaped update finds minority neighbours by the mask; the own
        // update reads them off the sums it fetches anyway.
        let minority = if options.fuse_minority && matches!(store, Store::Shaped(_)) {
            CellMask::of(
                cells
                    .iter()
                    .filter(|(_, s)| s.count < MIN_POINTS)
                    .map(|(k, _)| k),
            )
        } else {
            CellMask::default()
        };
        Self {
            options,
            level,
            cell_size,
            shape_depth: shape.map_or(0, |s| s.depth()),
            store,
            minority,
            seen: KeyScratch::default(),
        }
    }

    /// Levels between these distributions' level and their shape level (0:
    /// none applies).
    pub fn shape_depth(&self) -> usize {
        self.shape_depth
    }

    /// Recomputes the cells whose distribution may have changed after the
    /// cells `touched` gained or lost points: those cells, with fusion their 8
    /// neighbours (whose fused sums include them), and with a shape level the
    /// touched cells' ancestors (`shape`: that level, whose cells must
    /// already include the change; the same depth as at build; its changed
    /// cells in `touched.ancestors`). An ancestor
    /// whose shape changed only in value is written once for all the cells
    /// under it ([`crate::shaped`]); one that gained or lost its shape sets
    /// every cell under it again.
    /// `shapes` keeps the ancestors' shapes for the other levels updated
    /// after the same change (see [`ShapeMemo`]).
    pub fn update(
        &mut self,
        cells: &CellTable<CellStats>,
        cell_size: f64,
        touched: Changed<'_>,
        shape: Option<Shape<'_>>,
        shapes: &mut ShapeMemo,
    ) {
        let options = self.options;
        let seen = self.seen.take();
        match (&mut self.store, shape) {
            (Store::Shaped(store), Some(s)) => {
                let search = Search {
                    minority: &mut self.minority,
                    seen,
                };
                let shapes = shapes.reader(s, options.sigma_floor, options.expansion);
                update_shaped(store, search, cells, cell_size, options, touched, shapes);
            }
            (Store::Own(map), _) => {
                update_own(map, seen, cells, cell_size, options, touched.keys);
            }
            // Built with a shape level, updated without one: cannot happen
            // (the grid passes the same depth); rebuild rather than go stale.
            (Store::Shaped(_), None) => {
                *self = Self::build(cells, cell_size, self.level, options, None);
            }
        }
    }

    /// The options these distributions were built with.
    pub fn options(&self) -> DistOptions {
        self.options
    }

    /// The pyramid level these distributions belong to (0 = fine).
    pub fn level(&self) -> usize {
        self.level
    }

    /// Cell size \[m\].
    pub fn cell_size(&self) -> f64 {
        self.cell_size
    }

    /// The distribution of cell `key`, if it has one.
    #[inline]
    pub fn get(&self, key: CellKey) -> Option<Gaussian> {
        self.cursor().get(key)
    }

    /// A reader for runs of look-ups (a scan's points in order, a cell's
    /// neighbours): see [`crate::table::Cursor`].
    #[inline]
    pub fn cursor(&self) -> DistCursor<'_> {
        match &self.store {
            Store::Own(map) => DistCursor(CursorKind::Own(OwnCursor(map.cursor()))),
            Store::Shaped(store) => DistCursor(CursorKind::Shaped(store.cursor())),
        }
    }

    /// Bytes these distributions hold on the heap, look-up structure included.
    pub fn heap_bytes(&self) -> usize {
        let store = match &self.store {
            Store::Own(map) => map.heap_bytes(),
            Store::Shaped(store) => store.heap_bytes(),
        };
        store + self.minority.heap_bytes()
    }

    /// Number of cells with a distribution.
    pub fn len(&self) -> usize {
        match &self.store {
            Store::Own(map) => map.len(),
            Store::Shaped(store) => store.len(),
        }
    }

    /// Number of cells these distributions hold without reallocating.
    pub fn capacity(&self) -> usize {
        match &self.store {
            Store::Own(map) => map.capacity(),
            Store::Shaped(store) => store.capacity(),
        }
    }

    /// `true` when no cell has a distribution.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Reads [`Distributions`] for runs of look-ups (see [`crate::table::Cursor`]).
#[derive(Debug)]
pub struct DistCursor<'a>(CursorKind<'a>);

#[derive(Debug)]
enum CursorKind<'a> {
    Own(OwnCursor<'a>),
    Shaped(ShapedCursor<'a>),
}

impl DistCursor<'_> {
    /// The distribution of cell `key`, if it has one.
    #[inline]
    pub fn get(&mut self, key: CellKey) -> Option<Gaussian> {
        match &mut self.0 {
            CursorKind::Own(c) => DistLookup::get(c, key).copied(),
            CursorKind::Shaped(c) => c.get(key),
        }
    }
}

/// Look-ups of distributions by cell, for code generic over how they are
/// kept (the matcher's inner loop: [`Distributions::visit`]).
pub trait DistLookup {
    /// What a look-up gives: a reference where the distribution is stored
    /// whole, a value where it is assembled.
    type Dist: std::borrow::Borrow<Gaussian> + Copy;
    /// The distribution of cell `key`, if it has one.
    fn get(&mut self, key: CellKey) -> Option<Self::Dist>;
    /// Calls `f` with the distribution of each of the 8 cells around `key`
    /// that has one, in the order of [`crate::table::RING1`].
    #[inline(always)]
    fn for_ring1(&mut self, key: CellKey, mut f: impl FnMut(Self::Dist)) {
        for (dx, dy) in crate::table::RING1 {
            if let Some(g) = self.get(key.offset(dx, dy)) {
                f(g);
            }
        }
    }
}

/// Code run with the reader of [`Distributions`] of whichever kind they are
/// ([`Distributions::visit`]): one branch per call instead of one per look-up.
pub trait CursorVisitor {
    /// What the code returns.
    type Out;
    /// Runs the code with `cursor`.
    fn visit<L: DistLookup>(self, cursor: L) -> Self::Out;
}

impl Distributions {
    /// Runs `visitor` with a reader of these distributions.
    #[inline]
    pub fn visit<V: CursorVisitor>(&self, visitor: V) -> V::Out {
        match &self.store {
            Store::Own(map) => visitor.visit(OwnCursor(map.cursor())),
            Store::Shaped(store) => visitor.visit(store.cursor()),
        }
    }
}

/// Reads distributions stored whole.
#[derive(Debug)]
pub struct OwnCursor<'a>(Cursor<'a, Line>);

impl<'a> DistLookup for OwnCursor<'a> {
    type Dist = &'a Gaussian;
    #[inline(always)]
    fn get(&mut self, key: CellKey) -> Option<&'a Gaussian> {
        self.0.get(key).map(|l| &l.0)
    }
    #[inline(always)]
    fn for_ring1(&mut self, key: CellKey, mut f: impl FnMut(&'a Gaussian)) {
        self.0.for_ring1(key, |l| f(&l.0));
    }
}

impl DistLookup for ShapedCursor<'_> {
    type Dist = Gaussian;
    #[inline(always)]
    fn get(&mut self, key: CellKey) -> Option<Gaussian> {
        ShapedCursor::get(self, key)
    }
    #[inline(always)]
    fn for_ring1(&mut self, key: CellKey, f: impl FnMut(Gaussian)) {
        ShapedCursor::for_ring1(self, key, f);
    }
}

impl DistLookup for DistCursor<'_> {
    type Dist = Gaussian;
    #[inline]
    fn get(&mut self, key: CellKey) -> Option<Gaussian> {
        DistCursor::get(self, key)
    }
}

/// [`Distributions::update`] without a shape level: the touched cells and,
/// with fusion, their minority neighbours (whose fused sums include them,
/// §IV-A(3)), each once. A touched cell's 3 × 3 block of sums, fetched for
/// its own distribution, also tells which of its neighbours are minority
/// cells (at least one point, fewer than [`MIN_POINTS`]).
fn update_own(
    map: &mut CellTable<Line>,
    seen: &mut KeySet,
    cells: &CellTable<CellStats>,
    cell_size: f64,
    options: DistOptions,
    touched: &[CellKey],
) {
    let mut cursor = cells.cursor();
    let none = CellStats::default();
    let mut batch = OwnBatch::new(cell_size, options, |key, g| match g {
        Some(g) => map.insert(key, Line(g)),
        None => {
            map.remove(key);
        }
    });
    for &key in touched {
        if !options.fuse_minority {
            if seen.insert(key) {
                batch.push(key, cursor.get(key).copied());
            }
            continue;
        }
        let block = cursor.block3(key, &none);
        if seen.insert(key) {
            batch.push(key, fused_or_own(&block, cell_size));
        }
        // The minority neighbours as bits (no branch per neighbour), then
        // each of them, now: their blocks lie in the tiles just read (the
        // sums are all final, so the order changes no distribution).
        let bits = block.iter().enumerate().fold(0u16, |b, (i, c)| {
            b | u16::from(minority_count(c.count)) << i
        });
        for n in block_cells(key, bits & !(1 << 4)) {
            if seen.insert(n) {
                batch.push(n, own_stats(&mut cursor, cell_size, options, n));
            }
        }
    }
    batch.finish();
}

/// What the minority-neighbour search of one update reads and keeps track
/// of: the level's minority cells and the keys met so far (emptied).
struct Search<'a> {
    minority: &'a mut CellMask,
    seen: &'a mut KeySet,
}

/// Whether a cell with sums `own` is a minority cell (§IV-A(3): fewer than
/// [`MIN_POINTS`] points; a cell without points is none).
#[inline]
fn is_minority(own: Option<&CellStats>) -> bool {
    own.is_some_and(|s| minority_count(s.count))
}

/// Whether `count` points make a minority cell: at least one, fewer than
/// [`MIN_POINTS`] (one compare, no branch).
#[inline(always)]
fn minority_count(count: u64) -> bool {
    count.wrapping_sub(1) < MIN_POINTS - 1
}

/// The cells of a 3 × 3 block around `key` whose bits are set in `bits`
/// (bit `3 · (dy + 1) + (dx + 1)` for the cell at offset `(dx, dy)`), row
/// by row.
#[inline]
fn block_cells(key: CellKey, mut bits: u16) -> impl Iterator<Item = CellKey> {
    std::iter::from_fn(move || {
        (bits != 0).then(|| {
            let i = bits.trailing_zeros() as i32;
            bits &= bits - 1;
            key.offset(i % 3 - 1, i / 3 - 1)
        })
    })
}

/// `touched`, and with fusion every minority neighbour of a touched cell
/// (only those use fused sums that include it) for which `wanted` holds; each
/// once, in the order met.
fn with_minority_neighbours(
    search: Search<'_>,
    options: DistOptions,
    touched: &[CellKey],
    mut wanted: impl FnMut(CellKey) -> bool,
) -> Vec<CellKey> {
    let Search { minority, seen } = search;
    let mut rest = Vec::with_capacity(touched.len() * 2);
    let mut reader = minority.reader();
    for &key in touched {
        if wanted(key) && seen.insert(key) {
            rest.push(key);
        }
        if options.fuse_minority {
            // The minority cells of the 3 × 3 block but the cell itself (met
            // above).
            for n in block_cells(key, reader.block3(key) & !(1 << 4)) {
                if wanted(n) && seen.insert(n) {
                    rest.push(n);
                }
            }
        }
    }
    rest
}

/// [`Distributions::update`] with a shape level (see there).
fn update_shaped(
    store: &mut ShapedStore,
    search: Search<'_>,
    cells: &CellTable<CellStats>,
    cell_size: f64,
    options: DistOptions,
    changed_cells: Changed<'_>,
    mut shapes: ShapeReader<'_, '_>,
) {
    let touched = changed_cells.keys;
    let s = shapes.shape();
    let depth = s.depth();
    let ancestor_of = |k: CellKey| crate::pyramid::coarse_key(k, depth);
    // The touched cells' ancestors, each once, as the pyramid listed them
    // (no look-up to meet each once): those whose kind changed set all their
    // cells again.
    debug_assert_eq!(
        changed_cells.ancestors,
        first_touch(
            touched.iter().map(|&k| ancestor_of(k)),
            &mut KeySet::default()
        ),
        "the shape level's changes are the touched cells' ancestors"
    );
    let mut changed = FxHashSet::default();
    for &at in changed_cells.ancestors {
        if store.set_ancestor(at, shapes.next(at, || shape_of_ancestor(s, at, options))) {
            changed.insert(at);
        }
    }
    if !changed.is_empty() {
        let mut private = Vec::new();
        for (at, key, own) in s.descendants(&changed) {
            if set_cell(store, cell_size, at, key, own) {
                private.push(key);
            }
        }
        own_distributions(cells, cell_size, options, &private, |key, g| {
            store.set_own(key, g);
        });
    }
    // What an ancestor is now, `None` when it changed kind (its cells are
    // set above) or holds no cell; the last one asked about remembered.
    let mut kinds = AncestorKinds::new(&changed, s.cells());
    // A new distribution of their own for those without a shape, and with
    // fusion for their minority neighbours without one (a cell gone or
    // changed changes its neighbours' fused sums). A touched cell inside its
    // ancestor (not on its border) has all 8 neighbours under the same
    // ancestor, so when that one is not shapeless neither the cell nor a
    // neighbour is wanted: such cells are left out of the search.
    let side = 1i32 << depth;
    // The step to the ancestors next to cell `k`'s along each axis: −1 or
    // 1 on a border of its ancestor, 0 inside.
    let across = |k: CellKey| {
        let step = |p: i32| i32::from(p == side - 1) - i32::from(p == 0);
        (step(k.ix & (side - 1)), step(k.iy & (side - 1)))
    };
    let mut searched = Vec::with_capacity(touched.len());
    // The touched cells whose minority flag changes (most keep theirs: a
    // read of the mask costs less than a write).
    let mut flips = Vec::new();
    let mut flags = search.minority.reader();
    // The other touched cells: gone, or a new mean under a shape; their
    // minority flags; those to search.
    let mut sums = ChangedSums::new(cells, changed_cells.indices);
    for (n, &key) in touched.iter().enumerate() {
        let own = sums.get(n, key);
        let at = ancestor_of(key);
        let kind = kinds.of(store, at);
        match (own, kind) {
            (None, _) => store.remove(key),
            (Some(stats), Some(Ancestor::Shaped(slot))) => {
                // The ancestor kept its kind (`kinds`: `None` otherwise),
                // so the cell holds no part of its own.
                if let Some(mean) = shared_mean(cell_size, key, stats) {
                    store.set_shared_again(key, mean, slot);
                }
            }
            _ => {}
        }
        if options.fuse_minority {
            let now = is_minority(own);
            if flags.contains(key) != now {
                flips.push((key, now));
            }
        }
        // Only cells under a shapeless ancestor are wanted: a cell is
        // searched when its own or one across its border is shapeless (and
        // holds cells: a touched cell on the border of empty space has no
        // neighbours there).
        let wanted_around = kind == Some(Ancestor::Unshaped) || {
            let (dx, dy) = across(key);
            let mut shapeless =
                |dx: i32, dy: i32| kinds.of(store, at.offset(dx, dy)) == Some(Ancestor::Unshaped);
            (dx != 0 && shapeless(dx, 0))
                || (dy != 0 && shapeless(0, dy))
                || (dx != 0 && dy != 0 && shapeless(dx, dy))
        };
        if wanted_around {
            searched.push(key);
        }
    }
    search.minority.set_pairs(flips);
    let unshaped = with_minority_neighbours(search, options, &searched, |k| {
        kinds.of(store, ancestor_of(k)) == Some(Ancestor::Unshaped)
    });
    own_distributions(cells, cell_size, options, &unshaped, |key, g| {
        store.set_own(key, g);
    });
}

/// The new sums of the changed cells of one level, in order ([`Changed`]):
/// by the index of their value where the pyramid gave it (no look-up),
/// else looked up. The pyramid's indices hold until its next change, which
/// comes after this update (checked against the keys in debug builds).
struct ChangedSums<'a> {
    cells: &'a CellTable<CellStats>,
    cursor: Cursor<'a, CellStats>,
    indices: Option<&'a [u32]>,
}

impl<'a> ChangedSums<'a> {
    fn new(cells: &'a CellTable<CellStats>, indices: Option<&'a [u32]>) -> Self {
        Self {
            cells,
            cursor: cells.cursor(),
            indices,
        }
    }

    /// The sums of the `n`-th changed cell, `key` (`None`: it has none).
    #[inline(always)]
    fn get(&mut self, n: usize, key: CellKey) -> Option<&'a CellStats> {
        match self.indices {
            Some(ix) => {
                let i = ix.get(n).copied();
                debug_assert_eq!(i.and_then(|i| self.cells.key(i)), Some(key));
                i.and_then(|i| self.cells.value(i))
            }
            None => self.cursor.get(key),
        }
    }
}

/// The kinds of ancestors during one shaped update (fixed by then),
/// remembered in 64 slots by the ancestor index's low 3 bits on each axis:
/// a cell's neighbours, and the touched cells' runs, lie under nearby
/// ancestors. Each miss is a hash probe: 245 an insert of `insert_case`
/// with 16 slots, 223 with 64 (benches/SPEED_LOG.md, session 43).
struct AncestorKinds<'a> {
    changed: &'a FxHashSet<CellKey>,
    /// The shape level's sums: which ancestors hold cells.
    top: Cursor<'a, CellStats>,
    memo: [(CellKey, Option<Ancestor>); 64],
}

impl<'a> AncestorKinds<'a> {
    fn new(changed: &'a FxHashSet<CellKey>, top: &'a CellTable<CellStats>) -> Self {
        // No ancestor index is i32::MIN (|index| < 2³⁰).
        let none = CellKey {
            ix: i32::MIN,
            iy: i32::MIN,
        };
        Self {
            changed,
            top: top.cursor(),
            memo: [(none, None); 64],
        }
    }

    /// `None` for an ancestor that changed kind in this update (its cells
    /// are set from scratch) or that holds no cell (an unshaped one without
    /// points): no cell under it is left to the update's loop.
    #[inline(always)]
    fn of(&mut self, store: &ShapedStore, at: CellKey) -> Option<Ancestor> {
        let slot = ((at.ix & 7) | (at.iy & 7) << 3) as usize;
        match self.memo.get(slot) {
            Some(&(k, kind)) if k == at => kind,
            _ => self.look_up(store, at, slot),
        }
    }

    /// [`AncestorKinds::of`] for an ancestor not remembered (out of line).
    #[inline(never)]
    fn look_up(&mut self, store: &ShapedStore, at: CellKey, slot: usize) -> Option<Ancestor> {
        let kind = if self.changed.contains(&at) {
            None
        } else {
            match store.ancestor(at) {
                Ancestor::Unshaped if self.top.get(at).is_none() => None,
                kind => Some(kind),
            }
        };
        if let Some(m) = self.memo.get_mut(slot) {
            *m = (at, kind);
        }
        kind
    }
}

/// Sets cell `key` (sums `own`) under ancestor `at` as the ancestor's kind
/// says (see [`Ancestor`]); `true` when the cell takes a distribution of its
/// own (an unshaped ancestor), which the caller gives it, with the others',
/// by [`own_distributions`].
fn set_cell(
    store: &mut ShapedStore,
    cell_size: f64,
    at: CellKey,
    key: CellKey,
    own: &CellStats,
) -> bool {
    match store.ancestor(at) {
        Ancestor::Shaped(slot) => set_shared(store, cell_size, key, own, slot),
        Ancestor::Blocked => store.remove(key),
        Ancestor::Unshaped => return true,
    }
    false
}

/// Cell `key` (sums `own`) takes its own mean and the shared part `slot`
/// (as [`Gaussian::from_shape`] gives it).
fn set_shared(store: &mut ShapedStore, cell_size: f64, key: CellKey, own: &CellStats, slot: u32) {
    if let Some(mean) = shared_mean(cell_size, key, own) {
        store.set_shared(key, mean, slot);
    }
}

/// The map-frame mean of cell `key` with sums `own` (about its centre), as a
/// shaped distribution takes it; `None` without points.
#[inline]
fn shared_mean(cell_size: f64, key: CellKey, own: &CellStats) -> Option<Vector2<f64>> {
    own.mean().map(|mean| key.center(cell_size) + mean)
}

/// The covariance part of the shaped distributions under ancestor `at`
/// ([`Gaussian::shape_of`]): `None` when the ancestor has fewer than
/// [`MIN_POINTS`] points (its cells keep their own distributions),
/// `Some(None)` when it has no distribution.
fn shape_of_ancestor(s: Shape<'_>, at: CellKey, options: DistOptions) -> AncestorShape {
    s.cells()
        .get(at)
        .filter(|a| a.count >= MIN_POINTS)
        .map(|region| Gaussian::shape_of(region, options.sigma_floor, options.expansion))
}

/// The sums the paper's distribution of cell `key` comes from (`None`
/// when it has no points): its own, or for a minority cell with fusion
/// (§IV-A(3)) those of its 3 × 3 block about its centre ([`fused_or_own`]).
#[inline]
fn own_stats(
    cursor: &mut Cursor<'_, CellStats>,
    cell_size: f64,
    options: DistOptions,
    key: CellKey,
) -> Option<CellStats> {
    if !options.fuse_minority {
        return cursor.get(key).copied();
    }
    let none = CellStats::default();
    fused_or_own(&cursor.block3(key, &none), cell_size)
}

/// With fusion, the sums a cell's distribution comes from, from its 3 × 3
/// block (row by row, empty sums for a cell without points): `None` when
/// the cell itself has no points, its own sums with at least
/// [`MIN_POINTS`], else the block's about its centre (see
/// [`crate::gather`]).
#[inline]
fn fused_or_own(block: &[&CellStats; 9], cell_size: f64) -> Option<CellStats> {
    // A cell with points has a count; empty sums have none.
    let own = block[4];
    if own.count == 0 {
        None
    } else if own.count >= MIN_POINTS {
        Some(*own)
    } else {
        Some(gather::block3(block, cell_size))
    }
}

/// The paper's distribution of each cell of `keys` under `options`, from
/// the sums alone ([`own_stats`]); `emit` takes each key with its
/// distribution (`None`: it has none), in order.
fn own_distributions(
    cells: &CellTable<CellStats>,
    cell_size: f64,
    options: DistOptions,
    keys: &[CellKey],
    emit: impl FnMut(CellKey, Option<Gaussian>),
) {
    let mut cursor = cells.cursor();
    let mut batch = OwnBatch::new(cell_size, options, emit);
    for &key in keys {
        batch.push(key, own_stats(&mut cursor, cell_size, options, key));
    }
    batch.finish();
}

/// Cells waiting for their distributions: eq. (7) expanded by eq. (8) from
/// their sums, [`moments::BATCH`] cells at a time ([`moments::gaussians`]);
/// `emit` takes each key with its distribution, in the order pushed.
struct OwnBatch<F: FnMut(CellKey, Option<Gaussian>)> {
    cell_size: f64,
    options: DistOptions,
    keys: [CellKey; moments::BATCH],
    len: usize,
    stats: StatsBatch,
    out: GaussBatch,
    emit: F,
}

impl<F: FnMut(CellKey, Option<Gaussian>)> OwnBatch<F> {
    fn new(cell_size: f64, options: DistOptions, emit: F) -> Self {
        Self {
            cell_size,
            options,
            keys: [CellKey { ix: 0, iy: 0 }; moments::BATCH],
            len: 0,
            stats: StatsBatch::default(),
            out: GaussBatch::default(),
            emit,
        }
    }

    /// Cell `key`, whose distribution comes from the sums `s` about its
    /// centre (`None`: it has no points, so as empty sums it gets none).
    #[inline]
    fn push(&mut self, key: CellKey, s: Option<CellStats>) {
        if self.len == moments::BATCH {
            self.flush();
        }
        let l = self.len;
        self.stats
            .set(l, &s.unwrap_or_default(), key.center(self.cell_size));
        if let Some(k) = self.keys.get_mut(l) {
            *k = key;
        }
        self.len += 1;
    }

    fn flush(&mut self) {
        if self.len == 0 {
            return;
        }
        let (floor, k) = (self.options.sigma_floor, self.options.expansion);
        moments::gaussians(&self.stats, floor, k, &mut self.out);
        for (l, &key) in self.keys.iter().enumerate().take(self.len) {
            (self.emit)(key, self.out.get(l));
        }
        self.len = 0;
    }

    fn finish(mut self) {
        self.flush();
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::grid::NdtGrid;
    use crate::se2::Pose2;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Every level's kept distributions equal a fresh build, cell by cell.
    fn assert_as_built(grid: &NdtGrid, options: DistOptions) {
        let fresh = NdtGrid::from_cell_states(grid.cell_size(), &grid.cell_states()).unwrap();
        for level in 0..grid.levels() {
            let kept = grid.distributions(level, options).unwrap();
            let built = fresh.distributions(level, options).unwrap();
            assert_eq!(kept.len(), built.len(), "level {level}");
            let cells = grid
                .level(level)
                .map(|l| l.cells().keys().collect::<Vec<_>>());
            for key in cells.unwrap_or_default() {
                assert_eq!(kept.get(key), built.get(key), "level {level} cell {key:?}");
            }
        }
    }

    /// A level's distributions are built with the room its sums have: a table
    /// built exactly full was copied whole by the first insert that added a
    /// cell to the level, and by every insert into a fresh copy of a grid
    /// (criterion's `insert` group; benches/SPEED_LOG.md, session 52).
    #[test]
    fn a_built_table_has_the_room_of_its_sums_and_keeps_it_through_an_insert() {
        for shape_cell in [0.32, 0.0] {
            let options = DistOptions {
                expansion: 10.0,
                fuse_minority: true,
                sigma_floor: 0.005,
                shape_cell,
            };
            let mut grid = NdtGrid::new(0.02).unwrap();
            // 100 fine cells, every other one along a line, 3 points each
            // (a distribution of its own without a shape level).
            let cell = |x: f64| [[x + 0.003, 0.004], [x + 0.009, 0.015], [x + 0.015, 0.009]];
            let pts: Vec<[f64; 2]> = (0..100).flat_map(|i| cell(f64::from(i) * 0.04)).collect();
            grid.insert(&pts, Pose2::identity()).unwrap();
            let sums = grid.level(0).unwrap().cells();
            let (cells, room) = (sums.len(), sums.capacity());
            assert!(
                room > cells,
                "{room} > {cells}: the case needs room to spare"
            );
            let built = grid.distributions(0, options).unwrap();
            assert_eq!(built.len(), cells, "shape_cell {shape_cell}");
            assert_eq!(built.capacity(), room, "shape_cell {shape_cell}");
            drop(built);
            // Three points in a new cell between two others: the sums keep
            // their room, and so do the distributions kept up to date.
            grid.insert(&cell(0.02), Pose2::identity()).unwrap();
            assert_eq!(grid.level(0).unwrap().cells().capacity(), room);
            let kept = grid.distributions(0, options).unwrap();
            assert_eq!(kept.len(), cells + 1, "shape_cell {shape_cell}");
            assert_eq!(kept.capacity(), room, "shape_cell {shape_cell}");
        }
    }

    /// Inserts and removals that take ancestors across the 3-point bound both
    /// ways, make some shapeless (coincident points with a σ floor of
    /// 1e-200: no finite distribution) and move cells in and out of fusion.
    #[test]
    fn kept_distributions_equal_a_fresh_build_under_inserts_and_removals() {
        for (shape_cell, sigma_floor, fuse_minority) in [
            (0.32, 0.02, true),
            (0.32, 0.02, false),
            (0.08, 1e-200, true),
            (0.0, 0.005, true),
        ] {
            let options = DistOptions {
                expansion: 10.0,
                fuse_minority,
                sigma_floor,
                shape_cell,
            };
            let mut rng = StdRng::seed_from_u64(11);
            let mut grid = NdtGrid::new(0.02).unwrap();
            grid.insert(&[[0.0, 0.0]], Pose2::identity()).unwrap();
            for step in 0..60 {
                // Prepare every level, then change the map under them.
                for level in 0..grid.levels() {
                    let _ = grid.distributions(level, options);
                }
                if step % 4 == 3 {
                    let keys: Vec<CellKey> = grid.keys().filter(|_| rng.random_bool(0.3)).collect();
                    grid.remove_cells(&keys);
                } else {
                    // A few clusters of 1 to 4 points, some coincident.
                    let mut pts = Vec::new();
                    for _ in 0..rng.random_range(1..6) {
                        let c = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
                        for _ in 0..rng.random_range(1..5) {
                            if rng.random_bool(0.5) {
                                pts.push(c);
                            } else {
                                pts.push([c[0] + rng.random_range(-0.05..0.05), c[1]]);
                            }
                        }
                    }
                    grid.insert(&pts, Pose2::identity()).unwrap();
                }
                assert_as_built(&grid, options);
            }
        }
    }
}
