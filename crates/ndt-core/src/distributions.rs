//! The normal distributions the matcher pairs points with, derived from the
//! grid's sums: eq. (7) per cell, expanded by `k` (eq. 8), for cells with
//! fewer than 3 points the fused distribution of §IV-A(3), and for cells
//! finer than the shape scale the covariance of their ancestor
//! ([`crate::shape`]).

use nalgebra::Vector2;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::cell::{CellStats, Gaussian, MIN_POINTS};
use crate::cellmask::CellMask;
use crate::key::CellKey;
use crate::shape::Shape;
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

/// The distribution of every cell that has one, for one [`DistOptions`].
#[derive(Debug, Clone)]
pub struct Distributions {
    options: DistOptions,
    level: usize,
    cell_size: f64,
    /// Levels up to the shape level (0: no shape level applies).
    shape_depth: usize,
    map: CellTable<Gaussian>,
    /// The level's minority cells (with fusion; empty without).
    minority: CellMask,
}

impl Distributions {
    /// Builds the distributions of all cells; `shape`: the ancestors whose
    /// covariance they take (see [`crate::shape`]), if a shape level applies.
    pub fn build(
        cells: &FxHashMap<CellKey, CellStats>,
        cell_size: f64,
        level: usize,
        options: DistOptions,
        shape: Option<Shape<'_>>,
    ) -> Self {
        let mut map = CellTable::with_capacity(cells.len());
        let mut shapes = ShapeCache::default();
        for &key in cells.keys() {
            if let Some(g) = distribution_of(cells, cell_size, options, shape, &mut shapes, key) {
                map.insert(key, g);
            }
        }
        let minority = if options.fuse_minority {
            CellMask::of(
                cells
                    .iter()
                    .filter(|(_, s)| s.count < MIN_POINTS)
                    .map(|(k, _)| *k),
            )
        } else {
            CellMask::default()
        };
        Self {
            options,
            level,
            cell_size,
            shape_depth: shape.map_or(0, |s| s.depth()),
            map,
            minority,
        }
    }

    /// Levels between these distributions' level and their shape level (0:
    /// none applies).
    pub fn shape_depth(&self) -> usize {
        self.shape_depth
    }

    /// Recomputes the cells whose distribution may have changed after the
    /// cells `touched` gained or lost points: those cells, with fusion their 8
    /// neighbours (whose fused sums include them), and with a shape level
    /// every cell under the same ancestors (`shape`: that level, whose cells
    /// must already include the change; the same depth as at build).
    pub fn update(
        &mut self,
        cells: &FxHashMap<CellKey, CellStats>,
        cell_size: f64,
        touched: &[CellKey],
        shape: Option<Shape<'_>>,
    ) {
        let mut shapes = ShapeCache::default();
        // With a shape level: every cell under a touched ancestor (the
        // touched cells that still exist among them), each once.
        let mut ancestors = FxHashSet::default();
        if let Some(s) = shape {
            ancestors = touched
                .iter()
                .map(|&k| crate::pyramid::coarse_key(k, s.depth()))
                .collect();
            // Each ancestor's shape once, then its cells (as distribution_of
            // would give them; cells of an ancestor without a shape of its
            // own take the paper's distribution there).
            let mut current: Option<(CellKey, Option<Option<Gaussian>>)> = None;
            for (ancestor, key, own) in s.descendants(&ancestors) {
                let shaped = match current {
                    Some((a, shaped)) if a == ancestor => shaped,
                    _ => {
                        let shaped = shape_of_ancestor(s, ancestor, self.options);
                        current = Some((ancestor, shaped));
                        shaped
                    }
                };
                match shaped {
                    Some(covariance) => match in_shape(own, key.center(cell_size), &covariance) {
                        Some(g) => self.map.insert(key, g),
                        None => self.map.remove(key),
                    },
                    None => self.recompute(cells, cell_size, shape, &mut shapes, key),
                }
            }
        }
        // The rest: touched cells not covered above (all of them without a
        // shape level; with one, those that lost their last point), and with
        // fusion the minority neighbours, whose fused sums include them.
        let covered = |k: &CellKey| match shape {
            Some(s) => {
                cells.contains_key(k)
                    && ancestors.contains(&crate::pyramid::coarse_key(*k, s.depth()))
            }
            None => false,
        };
        // In the order met (a scan's cells come in runs along its surfaces,
        // so consecutive inserts mostly share a tile of the table).
        let mut seen: FxHashSet<CellKey> =
            FxHashSet::with_capacity_and_hasher(touched.len() * 2, Default::default());
        let mut rest = Vec::with_capacity(touched.len() * 2);
        let mut add = |k: CellKey| {
            if seen.insert(k) {
                rest.push(k);
            }
        };
        if self.options.fuse_minority {
            for &key in touched {
                let minority = cells.get(&key).is_some_and(|s| s.count < MIN_POINTS);
                self.minority.set(key, minority);
            }
        }
        let mut minority = self.minority.reader();
        for &key in touched {
            if !covered(&key) {
                add(key);
            }
            if self.options.fuse_minority {
                // Only minority neighbours use the fused sums that include `key`.
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let n = key.offset(dx, dy);
                        if minority.contains(n) && !covered(&n) {
                            add(n);
                        }
                    }
                }
            }
        }
        for key in rest {
            self.recompute(cells, cell_size, shape, &mut shapes, key);
        }
    }

    /// Sets (or removes) the distribution of `key` from the sums.
    fn recompute(
        &mut self,
        cells: &FxHashMap<CellKey, CellStats>,
        cell_size: f64,
        shape: Option<Shape<'_>>,
        shapes: &mut ShapeCache,
        key: CellKey,
    ) {
        match distribution_of(cells, cell_size, self.options, shape, shapes, key) {
            Some(g) => self.map.insert(key, g),
            None => self.map.remove(key),
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
    pub fn get(&self, key: CellKey) -> Option<&Gaussian> {
        self.map.get(key)
    }

    /// A reader for runs of look-ups (a scan's points in order, a cell's
    /// neighbours): see [`crate::table::Cursor`].
    #[inline]
    pub fn cursor(&self) -> Cursor<'_, Gaussian> {
        self.map.cursor()
    }

    /// Bytes these distributions hold on the heap, look-up structure included.
    pub fn heap_bytes(&self) -> usize {
        self.map.heap_bytes() + self.minority.heap_bytes()
    }

    /// Number of cells with a distribution.
    pub fn len(&self) -> usize {
        self.map.len()
    }

    /// `true` when no cell has a distribution.
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }
}

/// The covariance part of each ancestor's shaped distribution
/// ([`Gaussian::shape_of`]), computed once per ancestor in a build or update
/// rather than once per fine cell under it: `None` when the ancestor has fewer
/// than [`MIN_POINTS`] points (its cells keep their own distributions),
/// `Some(None)` when it has no distribution.
type ShapeCache = FxHashMap<CellKey, Option<Option<Gaussian>>>;

/// The covariance part of the shaped distributions under ancestor `at` (see
/// [`ShapeCache`] for the two levels of `None`).
fn shape_of_ancestor(s: Shape<'_>, at: CellKey, options: DistOptions) -> Option<Option<Gaussian>> {
    s.cells()
        .get(&at)
        .filter(|a| a.count >= MIN_POINTS)
        .map(|region| Gaussian::shape_of(region, options.sigma_floor, options.expansion))
}

/// A cell's shaped distribution: its own mean, the ancestor's covariance
/// part (`None`: the ancestor has no distribution, nor has the cell).
fn in_shape(
    own: &CellStats,
    centre: Vector2<f64>,
    covariance: &Option<Gaussian>,
) -> Option<Gaussian> {
    Gaussian::from_shape(own, centre, covariance.as_ref()?)
}

/// The distribution of one cell under `options`, from the sums alone.
fn distribution_of(
    cells: &FxHashMap<CellKey, CellStats>,
    cell_size: f64,
    options: DistOptions,
    shape: Option<Shape<'_>>,
    shapes: &mut ShapeCache,
    key: CellKey,
) -> Option<Gaussian> {
    let own = cells.get(&key)?;
    let centre = key.center(cell_size);
    // Own mean, the ancestor's covariance (crate::shape), when the ancestor
    // has a distribution of its own (Gaussian::with_shape, bit for bit).
    if let Some(s) = shape {
        let at = crate::pyramid::coarse_key(key, s.depth());
        let shaped = shapes
            .entry(at)
            .or_insert_with(|| shape_of_ancestor(s, at, options));
        if let Some(covariance) = shaped {
            return in_shape(own, centre, covariance);
        }
    }
    if own.count >= MIN_POINTS || !options.fuse_minority {
        return Gaussian::from_stats(own, centre, options.sigma_floor, options.expansion);
    }
    // §IV-A(3): fuse the minority cell with its neighbours. The neighbours'
    // sums are about their own centres; re-express them about this one.
    let mut fused = CellStats::default();
    for dy in -1..=1 {
        for dx in -1..=1 {
            if let Some(s) = cells.get(&key.offset(dx, dy)) {
                let delta = Vector2::new(-f64::from(dx), -f64::from(dy)) * cell_size;
                fused.merge(&s.shifted(delta));
            }
        }
    }
    Gaussian::from_stats(&fused, centre, options.sigma_floor, options.expansion)
}
