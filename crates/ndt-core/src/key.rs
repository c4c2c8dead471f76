//! Integer cell indices of the sparse, unbounded lattice (§III-B).

use nalgebra::Vector2;

/// Largest admissible |cell index|. Leaves head-room so that neighbour offsets
/// and coarse levels never overflow `i32`.
pub const MAX_INDEX: i32 = 1 << 30;

/// `1.5 · 2⁵²`: adding it rounds to an integer held in the low mantissa bits.
const ROUND: f64 = 6_755_399_441_055_744.0;

/// `⌊v⌋` without a conversion instruction (they do not vectorise): adding
/// [`ROUND`] rounds `v` to the nearest integer, held in the low bits (exact
/// for |v| < 2⁵¹), then one down where that is above `v`. The same as
/// [`CellKey::of`]'s index wherever [`floor_in_range`] holds; meaningless
/// elsewhere.
#[inline(always)]
fn floor_by_rounding(v: f64) -> i32 {
    let r = v + ROUND;
    (r.to_bits() as i32).wrapping_sub(i32::from(r - ROUND > v))
}

/// Whether `|⌊v⌋| < MAX_INDEX` (false for NaN), without a branch.
#[inline(always)]
pub(crate) fn floor_in_range(v: f64) -> bool {
    let lim = f64::from(MAX_INDEX);
    // ⌊v⌋ > −lim ⇔ v ≥ 1 − lim; ⌊v⌋ < lim ⇔ v < lim; both false for NaN.
    v >= 1.0 - lim && v < lim
}

/// `⌊v⌋` as an index, and whether `|⌊v⌋| < MAX_INDEX` (false for NaN; the
/// index is meaningless then). The same value as `v.floor() as i32`, without
/// the libm call that CPUs without SSE4.1's `roundsd` (the default x86-64
/// target) make for `floor`, and without a branch, so loops over many points
/// can check them all at once.
#[inline(always)]
fn floor_index(v: f64) -> (i32, bool) {
    let ok = floor_in_range(v);
    // Saturating, and exact truncation toward zero when `ok`; the wrapping
    // subtraction keeps a saturated `t` far out of range from overflowing.
    let t = v as i32;
    (t.wrapping_sub(i32::from(f64::from(t) > v)), ok)
}

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
    /// The key of the cell holding `p` \[m\], or `None` when the index would
    /// exceed ±[`MAX_INDEX`] (or `p` is not finite).
    #[inline]
    pub fn of(p: Vector2<f64>, inv_cell_size: f64) -> Option<CellKey> {
        let (key, ok) = Self::of_flagged(p, inv_cell_size);
        ok.then_some(key)
    }

    /// [`CellKey::of`] without a branch: the key and whether it exists (the
    /// key is meaningless when it does not), for loops over many points
    /// that check them all at once.
    /// [`CellKey::of_flagged`] without a conversion instruction
    /// ([`floor_by_rounding`]), for loops the compiler vectorises: the same
    /// key wherever the flag holds.
    #[inline(always)]
    pub(crate) fn of_flagged_in_lanes(p: Vector2<f64>, inv_cell_size: f64) -> (CellKey, bool) {
        let (vx, vy) = (p.x * inv_cell_size, p.y * inv_cell_size);
        let key = CellKey {
            ix: floor_by_rounding(vx),
            iy: floor_by_rounding(vy),
        };
        (key, floor_in_range(vx) & floor_in_range(vy))
    }

    #[inline(always)]
    pub(crate) fn of_flagged(p: Vector2<f64>, inv_cell_size: f64) -> (CellKey, bool) {
        let (ix, okx) = floor_index(p.x * inv_cell_size);
        let (iy, oky) = floor_index(p.y * inv_cell_size);
        (CellKey { ix, iy }, okx & oky)
    }

    /// Centre of the cell \[m\].
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The index the libm `floor` gives, with the original bounds check.
    fn by_floor(v: f64) -> Option<i32> {
        let f = v.floor();
        (f.abs() < f64::from(MAX_INDEX)).then_some(f as i32)
    }

    #[test]
    fn floor_index_equals_libm_floor() {
        let lim = f64::from(MAX_INDEX);
        let mut cases = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.0 - 1e-16,
            -1e-300,
            1e-300,
            lim,
            -lim,
            lim - 1.0,
            1.0 - lim,
            0.5 - lim,
            -lim + 1.0 - 1e-7,
            lim - 1e-7,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e300,
            -1e300,
        ];
        let mut x: u64 = 1;
        for _ in 0..200_000 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            let scale = [1.0, 100.0, 1e6, 2e9][(x & 3) as usize];
            cases.push((2.0 * u - 1.0) * scale);
            // Near-integers, where truncation and floor differ.
            let n = ((x >> 20) % 2001) as f64 - 1000.0;
            cases.extend([n, n - f64::EPSILON * n.abs(), n + f64::EPSILON * n.abs()]);
        }
        for v in cases {
            let (t, ok) = floor_index(v);
            assert_eq!(ok.then_some(t), by_floor(v), "v = {v:e}");
            // A key is the index of both coordinates, where both exist.
            let key = CellKey::of(Vector2::new(v, 0.5), 1.0);
            assert_eq!(key.map(|k| k.ix), by_floor(v), "key, v = {v:e}");
        }
    }
}
