//! Integer cell indices of the sparse, unbounded lattice (§III-B).

use nalgebra::Vector2;

/// Largest admissible |cell index|. Leaves head-room so that neighbour offsets
/// and coarse levels never overflow `i32`.
pub const MAX_INDEX: i32 = 1 << 30;

/// The integer index `(⌊x / s⌋, ⌊y / s⌋)` of a cell of size `s` (floor division,
/// so correct for negative coordinates).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CellKey {
    /// Column index.
    pub ix: i32,
    /// Row index.
    pub iy: i32,
}

impl CellKey {
    /// The key of the cell holding `p` [m], or `None` when the index would
    /// exceed ±[`MAX_INDEX`] (or `p` is not finite).
    #[inline]
    pub fn of(p: Vector2<f64>, inv_cell_size: f64) -> Option<CellKey> {
        let fx = (p.x * inv_cell_size).floor();
        let fy = (p.y * inv_cell_size).floor();
        let lim = MAX_INDEX as f64;
        // NaN fails both comparisons and is rejected too.
        if fx.abs() < lim && fy.abs() < lim {
            Some(CellKey {
                ix: fx as i32,
                iy: fy as i32,
            })
        } else {
            None
        }
    }

    /// Centre of the cell [m].
    #[inline]
    pub fn center(self, cell_size: f64) -> Vector2<f64> {
        Vector2::new(
            (f64::from(self.ix) + 0.5) * cell_size,
            (f64::from(self.iy) + 0.5) * cell_size,
        )
    }

    /// The key offset by `(dx, dy)` cells.
    #[inline]
    pub fn offset(self, dx: i32, dy: i32) -> CellKey {
        CellKey {
            ix: self.ix + dx,
            iy: self.iy + dy,
        }
    }
}

/// An inclusive rectangle of cell indices: a superset of the occupied cells
/// of a grid (see [`crate::NdtGrid::key_bounds`]), so that walks along a beam
/// can skip the part that lies where no cell is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KeyBounds {
    /// Smallest `ix` and `iy`.
    pub min: CellKey,
    /// Largest `ix` and `iy`.
    pub max: CellKey,
}

impl KeyBounds {
    /// The bounds of the single cell `key`.
    pub fn of(key: CellKey) -> Self {
        Self { min: key, max: key }
    }

    /// The bounds grown to hold `key` too.
    pub fn including(self, key: CellKey) -> Self {
        Self {
            min: CellKey {
                ix: self.min.ix.min(key.ix),
                iy: self.min.iy.min(key.iy),
            },
            max: CellKey {
                ix: self.max.ix.max(key.ix),
                iy: self.max.iy.max(key.iy),
            },
        }
    }

    /// The bounds of `keys`, `None` when there are none.
    pub fn of_keys(keys: impl IntoIterator<Item = CellKey>) -> Option<Self> {
        keys.into_iter().fold(None, |b: Option<Self>, k| {
            Some(b.map_or_else(|| Self::of(k), |b| b.including(k)))
        })
    }
}
