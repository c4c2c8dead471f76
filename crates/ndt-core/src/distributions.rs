//! The normal distributions the matcher pairs points with, derived from the
//! grid's sums: eq. (7) per cell, expanded by `k` (eq. 8), and for cells with
//! fewer than 3 points the fused distribution of §IV-A(3).

use nalgebra::Vector2;
use rustc_hash::{FxHashMap, FxHashSet};

use crate::cell::{CellStats, Gaussian, MIN_POINTS};
use crate::key::CellKey;

/// What decides a cell's distribution besides its sums.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistOptions {
    /// `k` of eq. (8): both covariance eigenvalues are multiplied by it (≥ 1
    /// widens the basin; 1 is the original NDT).
    pub expansion: f64,
    /// §IV-A(3): a cell with fewer than 3 points takes the distribution of the
    /// summed eq. (6) terms of itself and its 8 neighbours.
    pub fuse_minority: bool,
    /// Smallest standard deviation of a distribution before expansion [m]
    /// (see [`crate::cell::DEFAULT_SIGMA_FLOOR`]).
    pub sigma_floor: f64,
}

/// The distribution of every cell that has one, for one [`DistOptions`].
#[derive(Debug, Clone)]
pub struct Distributions {
    options: DistOptions,
    level: usize,
    cell_size: f64,
    map: FxHashMap<CellKey, Gaussian>,
}

impl Distributions {
    /// Builds the distributions of all cells.
    pub fn build(
        cells: &FxHashMap<CellKey, CellStats>,
        cell_size: f64,
        level: usize,
        options: DistOptions,
    ) -> Self {
        let mut map = FxHashMap::default();
        map.reserve(cells.len());
        for &key in cells.keys() {
            if let Some(g) = distribution_of(cells, cell_size, options, key) {
                map.insert(key, g);
            }
        }
        Self {
            options,
            level,
            cell_size,
            map,
        }
    }

    /// Recomputes the cells whose distribution may have changed after the
    /// cells `touched` gained or lost points: those cells, and with fusion their 8
    /// neighbours (whose fused sums include them).
    pub fn update(
        &mut self,
        cells: &FxHashMap<CellKey, CellStats>,
        cell_size: f64,
        touched: &[CellKey],
    ) {
        let mut affected: FxHashSet<CellKey> = FxHashSet::default();
        for &key in touched {
            affected.insert(key);
            if self.options.fuse_minority {
                // Only minority neighbours use the fused sums that include `key`.
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let n = key.offset(dx, dy);
                        if cells.get(&n).is_some_and(|s| s.count < MIN_POINTS) {
                            affected.insert(n);
                        }
                    }
                }
            }
        }
        for key in affected {
            match distribution_of(cells, cell_size, self.options, key) {
                Some(g) => {
                    self.map.insert(key, g);
                }
                None => {
                    self.map.remove(&key);
                }
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

    /// Cell size [m].
    pub fn cell_size(&self) -> f64 {
        self.cell_size
    }

    /// The distribution of cell `key`, if it has one.
    #[inline]
    pub fn get(&self, key: CellKey) -> Option<&Gaussian> {
        self.map.get(&key)
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

/// The distribution of one cell under `options`, from the sums alone.
fn distribution_of(
    cells: &FxHashMap<CellKey, CellStats>,
    cell_size: f64,
    options: DistOptions,
    key: CellKey,
) -> Option<Gaussian> {
    let own = cells.get(&key)?;
    let centre = key.center(cell_size);
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
