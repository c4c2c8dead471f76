//! The multi-resolution pyramid: level ℓ has cells `2^ℓ` times the fine size,
//! and its sums are exact sums of the fine cells' eq. (6) terms (a coarse
//! cell's `M, m, S` is the sum over the fine cells it covers). No point is
//! stored, and no level is ever rebuilt: every insert adds to all levels.

use nalgebra::Vector2;

use crate::cell::CellStats;
use crate::gather;
use crate::key::{CellKey, KeyBounds};
use crate::occupancy::Occupancy;
use crate::scratch::KeyScratch;
use crate::spare::{clone_nested, clone_vec};
use crate::table::CellTable;

mod bookkeeping;

use bookkeeping::{ChangedIndices, Stamps};

/// Most levels a grid may have (fine level included).
pub const MAX_LEVELS: usize = 12;

/// Key vectors a pyramid keeps for its next updates ([`Pyramid::give_back`]).
const SPARE_KEYS: usize = 2 * MAX_LEVELS;

/// One level of the pyramid: cells of `cell_size` metres with their sums
/// about each cell's centre, in dense tiles ([`CellTable`]): a coarse cell's
/// 4 children always share a tile of the level below, and a scan's cells
/// come in runs along its surfaces, so most look-ups of an update skip the
/// hash.
#[derive(Debug, Clone)]
pub struct Level {
    cell_size: f64,
    cells: CellTable<CellStats>,
}

impl Level {
    /// Cell size of this level \[m\].
    pub fn cell_size(&self) -> f64 {
        self.cell_size
    }

    /// The sums of every occupied cell of this level, about each cell's centre.
    pub fn cells(&self) -> &CellTable<CellStats> {
        &self.cells
    }
}

/// The fine grid and its coarser levels.
#[derive(Debug)]
pub struct Pyramid {
    levels: Vec<Level>,
    /// A superset of the fine keys in use: grown by every insert, reset when
    /// the fine level empties (removals do not shrink it).
    bounds: Option<KeyBounds>,
    /// The occupied fine cells (see [`crate::occupancy`]).
    occupied: Occupancy,
    /// The keys an update has met (reused between updates).
    seen: KeyScratch,
    /// Emptied key vectors given back, the storage of the next updates'
    /// results: the odometry loop updates its matching grid every few
    /// scans, and each new vector took the allocator's lock, which the
    /// mapper's helper thread may hold (benches/SPEED_LOG.md, session 27).
    spare: Vec<Vec<CellKey>>,
    /// Per level, per index of a cell's value: the number of the last
    /// update that met the cell ([`Stamps`]).
    stamps: Stamps,
    /// Per level, the indices of the values of the cells the last update
    /// changed ([`Pyramid::changed_indices`]).
    changed: ChangedIndices,
    /// The cells an insert added to the fine level (reused between updates).
    fresh: Vec<CellKey>,
    /// The parents of one level's runs of changed cells (reused between
    /// updates; only as many entries as the level has runs are its own, the
    /// rest are older levels' and never read).
    runs: Vec<CellKey>,
    /// An insert's runs of points in one cell, with their sums (reused
    /// between updates).
    run_sums: Vec<(CellKey, CellStats)>,
}

/// A copy with the original's spare capacity, its reused storage included
/// (the `spare` module).
impl Clone for Pyramid {
    fn clone(&self) -> Self {
        Self {
            levels: self.levels.clone(),
            bounds: self.bounds,
            occupied: self.occupied.clone(),
            seen: self.seen.clone(),
            spare: clone_nested(&self.spare),
            stamps: self.stamps.clone(),
            changed: self.changed.clone(),
            fresh: clone_vec(&self.fresh),
            runs: clone_vec(&self.runs),
            run_sums: clone_vec(&self.run_sums),
        }
    }
}

/// A parent cell that had no value when it was met.
const NEW_PARENT: u32 = u32::MAX;

/// Runs whose storage a pyramid keeps between updates: a scan's, not a
/// whole map's (runs of points in one cell, [`Pyramid::add_fine`], 64 bytes
/// each; runs of changed cells under one parent, 8 bytes each).
const RUN_KEEP: usize = 4096;

/// Keeps at most [`RUN_KEEP`] runs of `runs`' storage, giving the rest
/// back.
fn keep_runs<T>(runs: &mut Vec<T>) {
    if runs.len() > RUN_KEEP {
        runs.truncate(RUN_KEEP);
        runs.shrink_to_fit();
    }
}

/// The key of the level-`level` cell covering fine cell `key`: an arithmetic
/// shift, i.e. floor division by `2^level` (correct for negative indices).
#[inline]
pub fn coarse_key(key: CellKey, level: usize) -> CellKey {
    CellKey {
        ix: key.ix >> level,
        iy: key.iy >> level,
    }
}

impl Pyramid {
    /// An empty pyramid of `levels` levels over fine cells of `cell_size` m.
    pub fn new(cell_size: f64, levels: usize) -> Self {
        let levels = (0..levels.clamp(1, MAX_LEVELS))
            .map(|l| Level {
                cell_size: cell_size * f64::from(1u32 << l),
                cells: CellTable::default(),
            })
            .collect();
        Self {
            levels,
            bounds: None,
            occupied: Occupancy::default(),
            seen: KeyScratch::default(),
            spare: Vec::with_capacity(SPARE_KEYS),
            stamps: Stamps::default(),
            changed: ChangedIndices::default(),
            fresh: Vec::new(),
            runs: Vec::new(),
            run_sums: Vec::new(),
        }
    }

    /// Key vectors done with (an update's results): the next updates' results
    /// take their storage. Those beyond the spares kept are freed.
    pub fn give_back(&mut self, keys: impl IntoIterator<Item = Vec<CellKey>>) {
        for mut k in keys {
            if self.spare.len() >= SPARE_KEYS {
                break;
            }
            if k.capacity() > 0 {
                k.clear();
                self.spare.push(k);
            }
        }
    }

    /// An empty key vector with room for `n` keys (a spare's storage).
    fn keys(&mut self, n: usize) -> Vec<CellKey> {
        let mut v = self.spare.pop().unwrap_or_default();
        v.reserve(n);
        v
    }

    /// A rectangle of fine keys holding every occupied fine cell (possibly
    /// more), `None` when the fine level is empty.
    pub fn bounds(&self) -> Option<KeyBounds> {
        self.bounds
    }

    /// Bytes on the heap of the updates' marks of the cells met (a byte a
    /// cell) and their scratch; the levels' own bytes are
    /// [`CellTable::heap_bytes`].
    pub fn marks_heap_bytes(&self) -> usize {
        self.stamps.heap_bytes()
            + self.changed.heap_bytes()
            + (self.fresh.capacity() + self.runs.capacity()) * std::mem::size_of::<CellKey>()
            + self.run_sums.capacity() * std::mem::size_of::<(CellKey, CellStats)>()
    }

    /// The indices among level `level`'s values (as
    /// [`crate::table::Cursor::index`] gives them) of the cells the last
    /// update ([`Pyramid::add`], [`Pyramid::remove`], or the grid's
    /// deferred refresh) changed there, in the order of the keys it returned
    /// for the level; `None` when that update removed a cell there (a
    /// removal moves an index) or, on the fine level, did not add the points
    /// itself. They hold until the pyramid changes again.
    pub fn changed_indices(&self, level: usize) -> Option<&[u32]> {
        self.changed.get(level)
    }

    /// The occupied fine cells.
    pub fn occupied(&self) -> &Occupancy {
        &self.occupied
    }

    /// Number of levels (1 = the fine grid only).
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// `false`: a pyramid always has its fine level.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Level `l` (0 = fine).
    pub fn level(&self, l: usize) -> Option<&Level> {
        self.levels.get(l)
    }

    /// Levels `range` (0 = fine), if the pyramid has them all.
    pub fn levels(&self, range: std::ops::RangeInclusive<usize>) -> Option<&[Level]> {
        self.levels.get(range)
    }

    /// The fine level.
    pub fn fine(&self) -> &Level {
        &self.levels[0]
    }

    /// eq. (6) on the fine level for map-frame points `w` whose fine keys
    /// are given (scan points come in beam order, so runs of points in the
    /// same cell are summed first and added with one look-up); then every
    /// coarser cell above a changed one is re-summed from its 4 children, so
    /// each level is a function of the fine cells alone (the same however the
    /// points were batched, and bit for bit the same after a save and load).
    ///
    /// Returns, per level, the keys of the cells that changed, each once; on
    /// a coarser level in the order of their first changed child on the
    /// level below, so an ancestor's place is that of its first changed
    /// descendant ([`crate::distributions::Changed::ancestors`] relies on
    /// it).
    pub fn add(&mut self, staged: &[(CellKey, Vector2<f64>)]) -> Vec<Vec<CellKey>> {
        let touched = self.add_fine(staged);
        self.refresh_parents(touched)
    }

    /// The fine level's part of [`Pyramid::add`]: eq. (6) for the points
    /// `staged`, the occupancy and the bounds; the coarser levels are left
    /// for [`Pyramid::refresh`]. Returns the fine cells that changed.
    pub(crate) fn add_fine(&mut self, staged: &[(CellKey, Vector2<f64>)]) -> Vec<CellKey> {
        let mut touched = self.keys(staged.len());
        self.stamps.next_call(self.levels.len());
        // At most one new cell a point.
        self.stamps
            .prepare(0, self.levels[0].cells.len() + staged.len());
        let stamps = &mut self.stamps;
        let fine = &mut self.levels[0];
        // Cells new to the level take the values' indices from here on (no
        // removal here: the indices hold for the whole call).
        let before = fine.cells.len();
        let fresh = &mut self.fresh;
        fresh.clear();
        let mut indices = self.changed.start(0);
        // Runs of points in one cell (scan points come in beam order) summed
        // first, each run written at `n - 1` at every point and kept by
        // moving `n` when the next point starts a new run: no branch per
        // point on where a run ends (that follows the map's shapes). Then
        // each run into its cell.
        let runs = &mut self.run_sums;
        if runs.len() < staged.len() {
            runs.resize(
                staged.len(),
                (CellKey { ix: 0, iy: 0 }, CellStats::default()),
            );
        }
        let mut n = 0;
        let mut last = None;
        let mut sums = CellStats::default();
        for &(key, w) in staged {
            let new = last != Some(key);
            last = Some(key);
            n += usize::from(new);
            sums = sums.kept_if(!new);
            sums.add_point(w - key.center(fine.cell_size));
            if let Some(r) = runs.get_mut(n.wrapping_sub(1)) {
                *r = (key, sums);
            }
        }
        for &(key, ref stats) in runs.iter().take(n) {
            let (i, cell) = fine.cells.index_or_default(key);
            cell.merge(stats);
            if stamps.first_meeting(0, i) {
                touched.push(key);
                indices.push(i);
                if i as usize >= before {
                    fresh.push(key);
                }
            }
        }
        // The storage of a scan's runs is kept, that of a larger insert's
        // (a whole map at once) given back.
        keep_runs(runs);
        // No removal here: the indices hold.
        self.changed.done(0, indices, true);
        // Only new cells change the occupancy, or can lie beyond the bounds.
        self.occupied.insert(&self.fresh);
        if let Some(added) = KeyBounds::of_keys(self.fresh.iter().copied()) {
            self.bounds = Some(match self.bounds {
                Some(b) => b.including(added.min).including(added.max),
                None => added,
            });
        }
        touched
    }

    /// Brings the coarser levels up to date after the fine cells `fine`
    /// changed by [`Pyramid::add_fine`] and [`Pyramid::remove_fine`] (in any
    /// number of calls, a cell possibly more than once): each coarser cell
    /// above them is re-summed once. The levels are then the same, bit for
    /// bit, as after [`Pyramid::add`] and [`Pyramid::remove`] call by call
    /// (a coarse cell is a function of the fine cells alone). Returns the
    /// changed keys per level (level 0: `fine`, each once).
    pub(crate) fn refresh(&mut self, fine: &[CellKey]) -> Vec<Vec<CellKey>> {
        let mut once = self.keys(fine.len());
        let seen = self.seen.take();
        once.extend(fine.iter().copied().filter(|&k| seen.insert(k)));
        self.changed.forget(0);
        self.refresh_parents(once)
    }

    /// Re-sums, level by level, every coarse cell above the changed fine
    /// cells `fine` from its 4 children on the level below (in a fixed order),
    /// dropping it when they are all gone. Returns the changed keys per level
    /// (each parent once, in the order of its first changed child).
    fn refresh_parents(&mut self, fine: Vec<CellKey>) -> Vec<Vec<CellKey>> {
        let mut touched_all: Vec<Vec<CellKey>> = Vec::with_capacity(self.levels.len());
        touched_all.push(fine);
        self.stamps.next_call(self.levels.len());
        for l in 1..self.levels.len() {
            let below = touched_all[l - 1].len();
            let mut changed = self.keys(below);
            // Per changed parent: the index of its value, or NEW_PARENT;
            // then the index of its new value.
            let mut slots = self.changed.start(l);
            // Parents that have no cell yet are kept apart by key.
            let new_parents = self.seen.take();
            let (lower_levels, upper_levels) = self.levels.split_at_mut(l);
            let (lower, upper) = (&lower_levels[l - 1], &mut upper_levels[0]);
            {
                self.stamps.prepare(l, upper.cells.len());
                let mut existing = upper.cells.direct_cursor();
                // Changed children come in runs under one parent: each run's
                // parent once, without a branch per child (whether a child
                // starts a run follows the map's shapes, which no predictor
                // learns). A write at `n` stays until a new parent moves `n`.
                // (The storage only grows: each entry is written before it
                // is read, so none is filled first.)
                let runs = &mut self.runs;
                let lower_keys = &touched_all[l - 1];
                if runs.len() < lower_keys.len() {
                    runs.resize(lower_keys.len(), CellKey { ix: 0, iy: 0 });
                }
                let mut n = 0;
                let mut last = None;
                for &child in lower_keys {
                    let parent = coarse_key(child, 1);
                    if let Some(r) = runs.get_mut(n) {
                        *r = parent;
                    }
                    n += usize::from(last != Some(parent));
                    last = Some(parent);
                }
                let runs = runs.get(..n).unwrap_or_default();
                // Each parent met first kept, again without a branch: the
                // entry at `n` is written, and kept by moving `n` past it.
                changed.resize(runs.len(), CellKey { ix: 0, iy: 0 });
                slots.resize(runs.len(), NEW_PARENT);
                let mut n = 0;
                for &parent in runs {
                    let (first, i) = match existing.index(parent) {
                        Some(i) => (self.stamps.first_meeting(l, i), i),
                        None => (new_parents.insert(parent), NEW_PARENT),
                    };
                    if let (Some(c), Some(s)) = (changed.get_mut(n), slots.get_mut(n)) {
                        (*c, *s) = (parent, i);
                    }
                    n += usize::from(first);
                }
                changed.truncate(n);
                slots.truncate(n);
            }
            // The 4 children of a parent share a tile: one tile look-up at most.
            let mut children = lower.cells.direct_cursor();
            let none = CellStats::default();
            // The values' indices hold until a removal moves one.
            let mut indices_hold = true;
            for (&parent, i) in changed.iter().zip(&mut slots) {
                // Children's sums are about their own centres, ±½ a child
                // cell from the parent's (crate::gather).
                let sum = gather::quad(&children.quad(parent, &none), lower.cell_size);
                if sum.count == 0 {
                    upper.cells.remove(parent);
                    indices_hold = false;
                } else if *i != NEW_PARENT && indices_hold {
                    upper.cells.set_at(*i, sum);
                } else {
                    upper.cells.insert(parent, sum);
                    if *i == NEW_PARENT {
                        // A new cell's value is pushed: the last one.
                        *i = (upper.cells.len() - 1) as u32;
                    }
                }
            }
            self.changed.done(l, slots, indices_hold);
            touched_all.push(changed);
        }
        // The runs' storage of a scan's change is kept, that of a larger
        // change's given back (as `add_fine`'s).
        keep_runs(&mut self.runs);
        touched_all
    }
}

impl Pyramid {
    /// Removes the fine cells `keys` and their sums from every coarser level
    /// (coarse cells re-summed from their children, see [`Pyramid::add`]).
    ///
    /// Returns, per level, the keys of the cells that changed (level 0: the
    /// fine cells actually removed).
    pub fn remove(&mut self, keys: &[CellKey]) -> Vec<Vec<CellKey>> {
        let removed = self.remove_fine(keys);
        self.refresh_parents(removed)
    }

    /// The fine level's part of [`Pyramid::remove`] (see
    /// [`Pyramid::add_fine`]). Returns the fine cells actually removed.
    pub(crate) fn remove_fine(&mut self, keys: &[CellKey]) -> Vec<CellKey> {
        let mut removed = self.keys(keys.len());
        let seen = self.seen.take();
        for &key in keys {
            if seen.insert(key) && self.levels[0].cells.remove(key).is_some() {
                removed.push(key);
            }
        }
        self.changed.forget(0);
        self.occupied.remove(&removed);
        if self.levels[0].cells.is_empty() {
            self.bounds = None;
        }
        removed
    }
}

impl Pyramid {
    /// Replaces every level: the fine level holds exactly `states` (sums about
    /// each cell's centre) and each coarser level is summed from the one below.
    pub fn set_fine(&mut self, states: &[(CellKey, CellStats)]) {
        self.levels[0].cells = states.iter().copied().collect();
        self.bounds = KeyBounds::of_keys(states.iter().map(|(k, _)| *k));
        self.occupied = Occupancy::of(states.iter().map(|(k, _)| *k));
        for level in &mut self.levels[1..] {
            level.cells.clear();
        }
        self.changed.forget(0);
        self.refresh_parents(states.iter().map(|(k, _)| *k).collect());
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::scratch::{first_touch, KeySet};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// `n` points uniform in the square of half-side `half` \[m\] about the
    /// origin, with their 2 cm cells.
    fn random_points(rng: &mut StdRng, n: usize, half: f64) -> Vec<(CellKey, Vector2<f64>)> {
        (0..n)
            .map(|_| {
                let w = Vector2::new(rng.random_range(-half..half), rng.random_range(-half..half));
                (CellKey::of(w, 50.0).unwrap(), w)
            })
            .collect()
    }

    /// The fine sums of an insert are its runs of points in one cell, each
    /// summed from empty sums in order and then added to its cell, bit for
    /// bit (a cell met again later in the scan takes a second run); an
    /// insert of more points than `RUN_KEEP` gives the runs' storage back.
    #[test]
    fn an_insert_adds_its_runs_of_points_bit_for_bit() {
        let mut rng = StdRng::seed_from_u64(9);
        let mut staged = Vec::new();
        for run in 0..150 {
            // Run 40 holds RUN_KEEP points, all in one cell.
            let len = if run == 40 {
                RUN_KEEP
            } else {
                rng.random_range(1..8)
            };
            let c = Vector2::new(f64::from(run % 37) * 0.02, f64::from(run % 5) * 0.02);
            for _ in 0..len {
                let w = c + Vector2::new(rng.random_range(0.0..0.02), rng.random_range(0.0..0.02));
                staged.push((CellKey::of(w, 50.0).unwrap(), w));
            }
        }
        assert!(staged.len() > RUN_KEEP);
        let mut expected: Vec<(CellKey, CellStats)> = Vec::new();
        let mut i = 0;
        while i < staged.len() {
            let key = staged[i].0;
            let mut run = CellStats::default();
            while i < staged.len() && staged[i].0 == key {
                run.add_point(staged[i].1 - key.center(0.02));
                i += 1;
            }
            match expected.iter_mut().find(|(k, _)| *k == key) {
                Some((_, s)) => s.merge(&run),
                None => expected.push((key, run)),
            }
        }
        let mut p = Pyramid::new(0.02, 2);
        let changed = p.add(&staged);
        assert_eq!(
            changed[0],
            expected.iter().map(|(k, _)| *k).collect::<Vec<_>>()
        );
        for (key, want) in &expected {
            let got = p.fine().cells().get(*key).unwrap();
            assert_eq!(got.bits(), want.bits(), "{key:?}");
        }
        assert!(
            p.run_sums.capacity() <= RUN_KEEP,
            "{}",
            p.run_sums.capacity()
        );
    }

    /// A change of more fine cells than `RUN_KEEP` (a whole map at once)
    /// gives back the storage of the parents' runs, and a smaller change
    /// after it lists its parents alone, though the storage still holds
    /// older runs beyond them.
    #[test]
    fn a_large_change_gives_the_parents_runs_back() {
        let mut rng = StdRng::seed_from_u64(5);
        let mut p = Pyramid::new(0.02, 3);
        let big = random_points(&mut rng, 3 * RUN_KEEP, 5.0);
        let changed = p.add(&big);
        assert!(changed[0].len() > RUN_KEEP, "{}", changed[0].len());
        assert!(p.runs.capacity() <= RUN_KEEP, "{}", p.runs.capacity());
        for n in [RUN_KEEP, 7, 300, 1] {
            let staged = random_points(&mut rng, n, 5.0);
            let changed = p.add(&staged);
            assert_parents_in_order(&changed);
        }
    }

    /// A pyramid given its results back returns the keys and holds the
    /// sums of one given nothing back, in the storage it was given (last
    /// given, first used); it keeps at most `SPARE_KEYS` vectors.
    #[test]
    fn given_back_storage_changes_no_result() {
        let mut rng = StdRng::seed_from_u64(3);
        let (mut reused, mut fresh) = (Pyramid::new(0.02, 4), Pyramid::new(0.02, 4));
        for round in 0..60 {
            let n = rng.random_range(1..300);
            let staged = random_points(&mut rng, n, 2.0);
            let removed: Vec<CellKey> = staged
                .iter()
                .step_by(3)
                .map(|(k, _)| CellKey { ix: k.ix + 1, ..*k })
                .collect();
            // A large vector given last (with room for it) is the storage
            // of the next result.
            reused.spare.truncate(SPARE_KEYS - 1);
            let big = Vec::with_capacity(5000);
            let at = big.as_ptr();
            reused.give_back([big]);
            let got = reused.add(&staged);
            assert_eq!(got, fresh.add(&staged), "round {round}");
            assert_eq!(got[0].as_ptr(), at);
            reused.give_back(got);
            let got = reused.remove(&removed);
            assert_eq!(got, fresh.remove(&removed), "round {round}");
            reused.give_back(got);
            assert!(reused.spare.len() <= SPARE_KEYS);
            assert!(reused.spare.iter().all(Vec::is_empty));
        }
        for l in 0..4 {
            let (a, b) = (reused.level(l).unwrap(), fresh.level(l).unwrap());
            assert_eq!(a.cells(), b.cells(), "level {l}");
        }
        reused.give_back((0..3 * SPARE_KEYS).map(|_| vec![CellKey { ix: 0, iy: 0 }]));
        assert_eq!(reused.spare.len(), SPARE_KEYS);
    }

    /// Checks the indices of the last update against the keys it returned:
    /// per level, either the index of each changed cell's value, in order,
    /// or none, and then (a removal moves indices) some changed cell was
    /// removed there; on the fine level none when `fine_indexed` is false.
    fn assert_changed_indices(p: &Pyramid, changed: &[Vec<CellKey>], fine_indexed: bool) {
        for (l, keys) in changed.iter().enumerate() {
            let cells = p.level(l).unwrap().cells();
            match p.changed_indices(l) {
                Some(ix) => {
                    assert!(l > 0 || fine_indexed, "the fine level is not indexed");
                    assert_eq!(ix.len(), keys.len(), "level {l}");
                    for (&i, &k) in ix.iter().zip(keys) {
                        assert_eq!(cells.key(i), Some(k), "level {l}");
                        assert_eq!(cells.value(i), cells.get(k), "level {l}");
                    }
                }
                None if l == 0 && !fine_indexed => {}
                None => assert!(
                    keys.iter().any(|&k| !cells.contains(k)),
                    "level {l}: no index, but no cell was removed"
                ),
            }
        }
    }

    /// Each level's changed cells are the parents of the level below's, each
    /// once, in the order of their first changed child (what the
    /// distributions take as the touched cells' ancestors).
    fn assert_parents_in_order(changed: &[Vec<CellKey>]) {
        for (l, pair) in changed.windows(2).enumerate() {
            let parents = first_touch(
                pair[0].iter().map(|&k| coarse_key(k, 1)),
                &mut KeySet::default(),
            );
            assert_eq!(pair[1], parents, "level {}", l + 1);
        }
    }

    /// An insert gives the indices of every level's changed cells; a
    /// removal those of the coarse levels where no cell went (a level that
    /// lost one gives none), a deferred refresh those of the coarse levels;
    /// and each level's changes are the parents of the level below's.
    #[test]
    fn changed_indices_point_at_the_changed_cells() {
        let mut rng = StdRng::seed_from_u64(7);
        let mut p = Pyramid::new(0.02, 4);
        let mut unindexed = 0;
        for _ in 0..40 {
            let n = rng.random_range(1..200);
            let staged = random_points(&mut rng, n, 0.5);
            let changed = p.add(&staged);
            assert_changed_indices(&p, &changed, true);
            assert_parents_in_order(&changed);
            assert!((0..4).all(|l| p.changed_indices(l).is_some()));
            p.give_back(changed);
            let gone: Vec<CellKey> = staged.iter().step_by(2).map(|(k, _)| *k).collect();
            let changed = p.remove(&gone);
            assert_changed_indices(&p, &changed, false);
            assert_parents_in_order(&changed);
            unindexed += (1..4).filter(|&l| p.changed_indices(l).is_none()).count();
            p.give_back(changed);
            let fine = p.add_fine(&staged);
            let changed = p.refresh(&fine);
            assert_changed_indices(&p, &changed, false);
            assert_parents_in_order(&changed);
        }
        assert!(unindexed > 0, "some removal emptied a coarse cell");
    }

    /// A cell met again exactly one cycle of the marks' numbers (255
    /// updates) after it was last met is met afresh: the marks were cleared
    /// at the wrap in between.
    #[test]
    fn a_cell_met_again_a_whole_cycle_later_is_new_to_the_update() {
        let (mut cycled, mut plain) = (Pyramid::new(0.02, 2), Pyramid::new(0.02, 2));
        let at = |x: f64| {
            let w = Vector2::new(x, 0.01);
            vec![(CellKey::of(w, 50.0).unwrap(), w)]
        };
        // The cell's update, then 254 more (126 inserts elsewhere, of 2
        // updates each, and one removal of nothing, of 1), then the cell's
        // again: 255 updates after its mark was set.
        let mut updates: Vec<Vec<(CellKey, Vector2<f64>)>> = vec![at(0.0)];
        updates.extend((0..126).map(|_| at(5.0)));
        for (i, staged) in updates.iter().enumerate() {
            assert_eq!(cycled.add(staged), plain.add(staged), "insert {i}");
        }
        let nothing = [CellKey { ix: 999, iy: 999 }];
        assert_eq!(cycled.remove(&nothing), plain.remove(&nothing));
        let again = cycled.add(&at(0.0));
        assert_eq!(again, plain.add(&at(0.0)));
        assert_eq!(again[0].len(), 1, "the cell is among the changed ones");
        assert_eq!(
            cycled.level(1).unwrap().cells(),
            plain.level(1).unwrap().cells()
        );
    }

    /// An update's marks of met cells are cleared when their number wraps
    /// (every 255 updates; 0 is never a number): a mark left before a wrap
    /// does not hide a cell from an update after it. Started 3 updates
    /// before the wrap and run through more than one more, a pyramid
    /// returns the keys and holds the sums of one started at 0, through
    /// inserts and removals of the same cells.
    #[test]
    fn marks_survive_the_wrap_of_their_number() {
        let (mut wrapped, mut plain) = (Pyramid::new(0.02, 4), Pyramid::new(0.02, 4));
        wrapped.stamps.call = u8::MAX - 3;
        let mut rng = StdRng::seed_from_u64(5);
        for round in 0..100 {
            let staged = random_points(&mut rng, 200, 0.3);
            assert_eq!(wrapped.add(&staged), plain.add(&staged), "round {round}");
            let removed: Vec<CellKey> = staged.iter().step_by(4).map(|(k, _)| *k).collect();
            assert_eq!(
                wrapped.remove(&removed),
                plain.remove(&removed),
                "round {round}"
            );
        }
        // 300 updates from 252: wrapped twice.
        assert_eq!(wrapped.stamps.call, 42, "the number wrapped");
        for l in 0..4 {
            let (a, b) = (wrapped.level(l).unwrap(), plain.level(l).unwrap());
            assert_eq!(a.cells(), b.cells(), "level {l}");
        }
    }
}
