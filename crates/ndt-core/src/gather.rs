//! The eq. (6) sums of several cells of one lattice added up about one
//! centre: the fused sums of §IV-A(3) from a minority cell's 3 × 3 block
//! ([`block3`]), and a coarse pyramid cell from its 4 children ([`quad`]).
//!
//! A cell keeps its sums `M, m, S` about its own centre `o + h e`, where `o`
//! is the centre they are gathered about, `h` the lattice step and `e` the
//! cell's offset in steps (in {−1, 0, 1}² for a 3 × 3 block, {−½, ½}² for
//! the children of a coarse cell). About `o`, a point `x` is
//! `(x − o − h e) + h e`, so
//!
//! - `m_o = m + h M e`,
//! - `S_o = S + h (e mᵀ + m eᵀ) + h² M e eᵀ`.
//!
//! Summed over the cells, the parts without `h` (`Σ m`, `Σ M e`, `Σ S`,
//! `Σ e mᵀ`, `Σ M e eᵀ`) take only additions and subtractions for such
//! offsets (and exact halvings), and `h` is applied once at the end, instead
//! of re-expressing every cell's sums about `o` on its own. The result is
//! the same sums up to rounding, and the same bits for the same cells: an
//! incremental update and a fresh build agree exactly.

use nalgebra::{Matrix2, Vector2};

use crate::cell::CellStats;

/// The `h`-free parts of gathered sums (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
struct Parts {
    count: u64,
    /// `Σ m`.
    m: Vector2<f64>,
    /// `Σ M e`.
    me: Vector2<f64>,
    /// `Σ S`.
    s: Matrix2<f64>,
    /// `Σ e mᵀ`.
    em: Matrix2<f64>,
    /// `Σ M e eᵀ` (symmetric): xx, xy, yy.
    mee: [f64; 3],
}

impl Parts {
    /// The sums about the centre on a lattice of step `h` \[m\].
    #[inline(always)]
    fn finish(&self, h: f64) -> CellStats {
        let (em, q, h2) = (&self.em, &self.mee, h * h);
        let cross = Matrix2::new(
            em[(0, 0)] + em[(0, 0)],
            em[(0, 1)] + em[(1, 0)],
            em[(1, 0)] + em[(0, 1)],
            em[(1, 1)] + em[(1, 1)],
        );
        let curvature = Matrix2::new(q[0], q[1], q[1], q[2]);
        CellStats {
            count: self.count,
            sum: self.m + self.me * h,
            scatter: self.s + cross * h + curvature * h2,
        }
    }
}

/// The sums of a 3 × 3 block of cells of step `h` \[m\] about the centre
/// cell's centre: `cells` row by row (`dy = −1` first, `dx = −1` first in a
/// row; as [`crate::table::Cursor::block3`] gives them), empty sums for a
/// cell without points (they add zeros: no branch on the irregular pattern
/// of cells).
#[inline]
pub fn block3(cells: &[&CellStats; 9], h: f64) -> CellStats {
    // Per row: M, m, and the column-weighted Σ M eₓ, Σ eₓ m, Σ M eₓ².
    let mut n = [0.0; 3];
    let mut m = [Vector2::zeros(); 3];
    let mut xn = [0.0; 3];
    let mut xm = [Vector2::zeros(); 3];
    let mut x2n = [0.0; 3];
    let mut s = Matrix2::zeros();
    let mut count = 0;
    for (r, row) in cells.chunks_exact(3).enumerate() {
        let [a, b, c] = [row[0], row[1], row[2]];
        count += a.count + b.count + c.count;
        let (ka, kb, kc) = (a.points(), b.points(), c.points());
        s += a.scatter + b.scatter + c.scatter;
        if let (Some(nr), Some(mr), Some(xnr), Some(xmr), Some(x2r)) = (
            n.get_mut(r),
            m.get_mut(r),
            xn.get_mut(r),
            xm.get_mut(r),
            x2n.get_mut(r),
        ) {
            *nr = ka + kb + kc;
            *mr = a.sum + b.sum + c.sum;
            *xnr = kc - ka;
            *xmr = c.sum - a.sum;
            *x2r = kc + ka;
        }
    }
    let (xm_all, m_dy) = (xm[0] + xm[1] + xm[2], m[2] - m[0]);
    Parts {
        count,
        m: m[0] + m[1] + m[2],
        me: Vector2::new(xn[0] + xn[1] + xn[2], n[2] - n[0]),
        s,
        em: Matrix2::new(xm_all.x, xm_all.y, m_dy.x, m_dy.y),
        mee: [x2n[0] + x2n[1] + x2n[2], xn[2] - xn[0], n[2] + n[0]],
    }
    .finish(h)
}

/// The sums of a coarse cell about its centre from its 4 children of step
/// `h` \[m\] (the order of [`crate::table::Cursor::quad`]: (0, 0), (1, 0),
/// (0, 1), (1, 1)), empty sums for a child without points (they add zeros).
#[inline]
pub fn quad(children: &[&CellStats; 4], h: f64) -> CellStats {
    let c = children;
    let count = c[0].count + c[1].count + c[2].count + c[3].count;
    let n = c.map(CellStats::points);
    let m = c.map(|c| c.sum);
    let s = c[0].scatter + c[1].scatter + c[2].scatter + c[3].scatter;
    // eₓ = ½ for children 1 and 3, −½ for 0 and 2; e_y = ½ for 2 and 3.
    let (right, left) = (n[1] + n[3], n[0] + n[2]);
    let (top, bottom) = (n[2] + n[3], n[0] + n[1]);
    let (m_right, m_left) = (m[1] + m[3], m[0] + m[2]);
    let (m_top, m_bottom) = (m[2] + m[3], m[0] + m[1]);
    let all = n[0] + n[1] + n[2] + n[3];
    let (ex_m, ey_m) = ((m_right - m_left) * 0.5, (m_top - m_bottom) * 0.5);
    Parts {
        count,
        m: m[0] + m[1] + m[2] + m[3],
        me: Vector2::new(right - left, top - bottom) * 0.5,
        s,
        em: Matrix2::new(ex_m.x, ex_m.y, ey_m.x, ey_m.y),
        mee: [all * 0.25, (n[0] + n[3] - n[1] - n[2]) * 0.25, all * 0.25],
    }
    .finish(h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Gathering equals re-expressing each cell's sums about the centre
    /// ([`CellStats::shifted`]) and summing, to rounding, and equals the sums
    /// of the points themselves about the centre: for 3 × 3 blocks and for a
    /// cell's 4 children, with empty cells, far from the origin too.
    #[test]
    fn equals_shifting_each_cell_and_the_points_own_sums() {
        let mut rng = StdRng::seed_from_u64(9);
        for trial in 0..400 {
            let h = [0.02, 0.04, 0.64][trial % 3];
            let far = if trial % 2 == 0 { 0.0 } else { 1234.5 };
            let centre = Vector2::new(
                far + rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let blocks = trial % 4 < 2;
            let offsets: Vec<Vector2<f64>> = if blocks {
                (0..9)
                    .map(|i| Vector2::new(f64::from(i % 3) - 1.0, f64::from(i / 3) - 1.0))
                    .collect()
            } else {
                (0..4)
                    .map(|i| Vector2::new(f64::from(i % 2) - 0.5, f64::from(i / 2) - 0.5))
                    .collect()
            };
            let mut cells = Vec::new();
            let mut shifted = CellStats::default();
            let mut direct = CellStats::default();
            for e in &offsets {
                let cell_centre = centre + e * h;
                let mut own = CellStats::default();
                for _ in 0..rng.random_range(0..4) {
                    let x = cell_centre
                        + Vector2::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5))
                            * h;
                    own.add_point(x - cell_centre);
                    direct.add_point(x - centre);
                }
                shifted.merge(&own.shifted(-e * h));
                cells.push(own);
            }
            let refs: Vec<&CellStats> = cells.iter().collect();
            let got = if blocks {
                let mut a = [&direct; 9];
                a.copy_from_slice(&refs);
                block3(&a, h)
            } else {
                let mut a = [&direct; 4];
                a.copy_from_slice(&refs);
                quad(&a, h)
            };
            assert_eq!(got.count, direct.count);
            // Against the shifted cells: rounding of the same sums. Against
            // the points: also the rounding of `x − centre` far out.
            let n = direct.count.max(1) as f64;
            for (b, tol) in [(shifted, 1e-14), (direct, 1e-15 * (1.0 + far) / h)] {
                assert!(
                    (got.sum - b.sum).abs().max() <= tol * n * h,
                    "{got:?} {b:?}"
                );
                assert!(
                    (got.scatter - b.scatter).abs().max() <= tol * n * h * h,
                    "{got:?} {b:?}"
                );
            }
        }
    }
}
