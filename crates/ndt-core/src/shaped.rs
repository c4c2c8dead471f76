//! Shaped distributions kept by reference (see [`crate::shape`]): a cell under
//! an ancestor with a shape stores only its own mean and the index of the
//! ancestor's covariance part (`Σ'⁻¹` of eq. 8 and the normal), which every
//! cell under that ancestor shares.
//!
//! A scan that adds points under a 32 cm ancestor changes the ancestor's
//! covariance, so every fine cell under it (a few dozen on each of the levels
//! 2, 4, 8 and 16 cm) has a new distribution. Stored as copies, each would be
//! rewritten on every insert; by reference the ancestor's part is written once
//! and only the cells whose own sums changed get a new mean. What a look-up
//! returns is the same [`Gaussian`], bit for bit, as the copy would be
//! ([`Gaussian::from_shape`]).
//!
//! Cells under an ancestor without a shape (fewer than 3 points, §III-B) keep
//! the paper's distribution of their own (eq. 7, fusion of §IV-A(3)): each has
//! a part of its own ("private").

use nalgebra::{Matrix2, Vector2};
use rustc_hash::FxHashMap;

use crate::cell::Gaussian;
use crate::key::CellKey;
use crate::spare::clone_vec;
use crate::table::{CellTable, Cursor};

/// The covariance part of a distribution: everything but its mean.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(align(64))]
struct Part {
    inverse: Matrix2<f64>,
    normal: Vector2<f64>,
}

impl Part {
    fn of(g: &Gaussian) -> Self {
        Self {
            inverse: g.inverse,
            normal: g.normal,
        }
    }
}

/// One cell: its mean and its part (`private`: the cell's own).
#[derive(Debug, Clone, Copy)]
#[repr(align(32))]
struct Entry {
    mean: Vector2<f64>,
    part: u32,
    private: bool,
}

impl Entry {
    /// A cell with mean `mean` taking the shared part `slot`.
    #[inline]
    fn shared(mean: Vector2<f64>, slot: u32) -> Self {
        Self {
            mean,
            part: slot,
            private: false,
        }
    }
}

/// What an ancestor gives the cells under it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ancestor {
    /// Fewer than [`crate::cell::MIN_POINTS`] points: each cell has the
    /// paper's distribution of its own.
    Unshaped,
    /// A shape: every cell under it takes part `0`.
    Shaped(u32),
    /// Enough points but no finite distribution (extreme `k` or σ floor): no
    /// cell under it has one.
    Blocked,
}

/// The distributions of one level with a shape level (see the module docs).
#[derive(Debug, Default)]
pub struct ShapedStore {
    cells: CellTable<Entry>,
    parts: Vec<Part>,
    free: Vec<u32>,
    /// The ancestors that are [`Ancestor::Shaped`] or [`Ancestor::Blocked`]
    /// (absent: unshaped).
    ancestors: FxHashMap<CellKey, Ancestor>,
}

/// A copy with the original's spare capacity (the `spare` module).
impl Clone for ShapedStore {
    fn clone(&self) -> Self {
        Self {
            cells: self.cells.clone(),
            parts: clone_vec(&self.parts),
            free: clone_vec(&self.free),
            ancestors: self.ancestors.clone(),
        }
    }
}

impl ShapedStore {
    /// An empty store with room for about `cells` cells.
    pub fn with_capacity(cells: usize) -> Self {
        Self {
            cells: CellTable::with_capacity(cells),
            ..Self::default()
        }
    }

    /// What ancestor `at` gives its cells.
    #[inline]
    pub fn ancestor(&self, at: CellKey) -> Ancestor {
        self.ancestors
            .get(&at)
            .copied()
            .unwrap_or(Ancestor::Unshaped)
    }

    /// Sets ancestor `at` from its shape ([`Gaussian::shape_of`]: `None`
    /// below 3 points, `Some(None)` without a finite distribution). Returns
    /// `true` when its kind changed, so that every cell under it must be set
    /// again ([`ShapedStore::set_shared`], [`ShapedStore::set_own`],
    /// [`ShapedStore::remove`]) before the store is read; a shape that only
    /// changed its value takes effect for all of them at once.
    pub fn set_ancestor(&mut self, at: CellKey, shape: Option<Option<Gaussian>>) -> bool {
        let old = self.ancestor(at);
        match (old, shape) {
            (Ancestor::Shaped(slot), Some(Some(g))) => {
                self.parts[slot as usize] = Part::of(&g);
                false
            }
            (_, Some(Some(g))) => {
                let slot = self.alloc(Part::of(&g));
                self.ancestors.insert(at, Ancestor::Shaped(slot));
                true
            }
            (old, new) => {
                if let Ancestor::Shaped(slot) = old {
                    self.free.push(slot);
                }
                let kind = match new {
                    Some(_) => Ancestor::Blocked,
                    None => Ancestor::Unshaped,
                };
                match kind {
                    Ancestor::Unshaped => self.ancestors.remove(&at),
                    _ => self.ancestors.insert(at, kind),
                };
                kind != old
            }
        }
    }

    /// Cell `key` with mean `mean` takes the shared part `slot` (of an
    /// [`Ancestor::Shaped`]).
    #[inline]
    pub fn set_shared(&mut self, key: CellKey, mean: Vector2<f64>, slot: u32) {
        if let Some(old) = self.cells.replace(key, Entry::shared(mean, slot)) {
            if old.private {
                self.free.push(old.part);
            }
        }
    }

    /// As [`ShapedStore::set_shared`] for a cell known to hold no part of
    /// its own (one under an ancestor that was [`Ancestor::Shaped`] before
    /// the change and still is: its cells all share that part): the entry
    /// is written without reading the one it replaces, so a write that
    /// misses the cache need not wait for the line.
    #[inline]
    pub fn set_shared_again(&mut self, key: CellKey, mean: Vector2<f64>, slot: u32) {
        debug_assert!(
            self.cells.get(key).is_none_or(|e| !e.private),
            "a cell under a shaped ancestor holds a part of its own"
        );
        self.cells.insert(key, Entry::shared(mean, slot));
    }

    /// Cell `key` has distribution `g` of its own (`None`: it has none).
    pub fn set_own(&mut self, key: CellKey, g: Option<Gaussian>) {
        let Some(g) = g else {
            self.remove(key);
            return;
        };
        let part = match self.cells.get(key) {
            Some(e) if e.private => {
                self.parts[e.part as usize] = Part::of(&g);
                e.part
            }
            _ => self.alloc(Part::of(&g)),
        };
        self.cells.insert(
            key,
            Entry {
                mean: g.mean,
                part,
                private: true,
            },
        );
    }

    /// Cell `key` has no distribution.
    pub fn remove(&mut self, key: CellKey) {
        if let Some(e) = self.cells.remove(key) {
            if e.private {
                self.free.push(e.part);
            }
        }
    }

    fn alloc(&mut self, part: Part) -> u32 {
        match self.free.pop() {
            Some(slot) => {
                self.parts[slot as usize] = part;
                slot
            }
            None => {
                self.parts.push(part);
                (self.parts.len() - 1) as u32
            }
        }
    }

    /// The distribution of cell `key`, if it has one.
    pub fn get(&self, key: CellKey) -> Option<Gaussian> {
        self.cursor().get(key)
    }

    /// A reader for runs of look-ups (see [`crate::table::Cursor`]).
    #[inline]
    pub fn cursor(&self) -> ShapedCursor<'_> {
        ShapedCursor {
            cells: self.cells.cursor(),
            parts: &self.parts,
        }
    }

    /// Number of cells with a distribution.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// Number of cells the store holds without reallocating its table.
    pub fn capacity(&self) -> usize {
        self.cells.capacity()
    }

    /// `true` when no cell has a distribution.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Bytes held on the heap, look-up structures included.
    pub fn heap_bytes(&self) -> usize {
        self.cells.heap_bytes()
            + self.parts.capacity() * std::mem::size_of::<Part>()
            + self.free.capacity() * 4
            + crate::table::hash_map_bytes(
                self.ancestors.capacity(),
                std::mem::size_of::<(CellKey, Ancestor)>(),
            )
    }
}

/// Reads a [`ShapedStore`]: the cell's entry through a tile cursor, then its
/// part (the parts of a scan's neighbourhood are few and stay in cache).
#[derive(Debug)]
pub struct ShapedCursor<'a> {
    cells: Cursor<'a, Entry>,
    parts: &'a [Part],
}

impl ShapedCursor<'_> {
    /// The distribution of cell `key`, if it has one.
    #[inline(always)]
    pub fn get(&mut self, key: CellKey) -> Option<Gaussian> {
        let e = self.cells.get(key)?;
        assemble(self.parts, e)
    }

    /// Calls `f` with the distribution of each of the 8 cells around `key`
    /// that has one (see [`crate::table::Cursor::for_ring1`]).
    #[inline(always)]
    pub fn for_ring1(&mut self, key: CellKey, mut f: impl FnMut(Gaussian)) {
        let parts = self.parts;
        self.cells.for_ring1(key, |e| {
            if let Some(g) = assemble(parts, e) {
                f(g);
            }
        });
    }
}

/// The distribution of a cell's entry: its mean with its part's covariance.
#[inline(always)]
fn assemble(parts: &[Part], e: &Entry) -> Option<Gaussian> {
    let p = parts.get(e.part as usize)?;
    Some(Gaussian {
        mean: e.mean,
        inverse: p.inverse,
        normal: p.normal,
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn g(v: f64) -> Gaussian {
        Gaussian {
            mean: Vector2::new(v, -v),
            inverse: Matrix2::new(v, 0.5, 0.5, 2.0 * v),
            normal: Vector2::new(0.0, 1.0),
        }
    }

    #[test]
    fn shared_parts_follow_their_ancestor_and_private_parts_are_reused() {
        let mut s = ShapedStore::default();
        let (a, k1, k2) = (
            CellKey { ix: 0, iy: 0 },
            CellKey { ix: 1, iy: 2 },
            CellKey { ix: 3, iy: 3 },
        );
        assert!(s.set_ancestor(a, Some(Some(g(1.0)))));
        let slot = match s.ancestor(a) {
            Ancestor::Shaped(slot) => slot,
            other => unreachable!("{other:?}"),
        };
        s.set_shared(k1, Vector2::new(0.1, 0.2), slot);
        s.set_shared(k2, Vector2::new(0.3, 0.4), slot);
        // A new value of the same kind: no rewrite, both cells see it.
        assert!(!s.set_ancestor(a, Some(Some(g(3.0)))));
        for (k, m) in [(k1, [0.1, 0.2]), (k2, [0.3, 0.4])] {
            let got = s.get(k).unwrap();
            assert_eq!(got.mean, Vector2::new(m[0], m[1]));
            assert_eq!(got.inverse, g(3.0).inverse);
        }
        // Unshaped: the cells get parts of their own; the shared one is freed.
        assert!(s.set_ancestor(a, None));
        assert_eq!(s.ancestor(a), Ancestor::Unshaped);
        s.set_own(k1, Some(g(5.0)));
        s.set_own(k2, None);
        assert_eq!(s.get(k1), Some(g(5.0)));
        assert_eq!(s.get(k2), None);
        assert_eq!(s.parts.len(), 1, "the freed shared slot was reused");
        s.set_own(k1, Some(g(6.0)));
        assert_eq!(s.get(k1), Some(g(6.0)));
        assert_eq!(s.parts.len(), 1, "a private part is overwritten in place");
        // Blocked, then shaped again.
        assert!(s.set_ancestor(a, Some(None)));
        assert_eq!(s.ancestor(a), Ancestor::Blocked);
        s.remove(k1);
        assert!(s.is_empty());
        assert!(!s.set_ancestor(a, Some(None)));
        assert!(s.set_ancestor(a, Some(Some(g(2.0)))));
        assert_eq!(s.parts.len(), 1);
    }
}
