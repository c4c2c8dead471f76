//! eq. (7) and (8) for a batch of cells at once: the same arithmetic as
//! [`Gaussian::from_stats`], lane by lane and without branches (the
//! eigenvector's case analysis and the validity checks become selects), so
//! the compiler runs [`BATCH`] cells side by side in SIMD registers. An
//! insert recomputes hundreds of distributions per pyramid level (the
//! touched cells and their minority neighbours, §IV-A(3)); one at a time,
//! each is a chain of divisions and square roots with data-dependent
//! branches.
//!
//! Every lane gives the bits [`Gaussian::from_stats`] gives for its cell
//! (the same operations in the same order; no fused multiply-add).

use multiversion::multiversion;
use nalgebra::{Matrix2, Vector2};

use crate::cell::{CellStats, Gaussian, EIGEN_RATIO, MIN_POINTS};

/// Cells per batch.
pub const BATCH: usize = 16;

/// The eq. (6) sums of [`BATCH`] cells (about their origins) and the
/// origins \[m\], one array per quantity.
#[derive(Debug, Clone, Copy, Default)]
pub struct StatsBatch {
    n: [f64; BATCH],
    sx: [f64; BATCH],
    sy: [f64; BATCH],
    s00: [f64; BATCH],
    s01: [f64; BATCH],
    s10: [f64; BATCH],
    s11: [f64; BATCH],
    ox: [f64; BATCH],
    oy: [f64; BATCH],
}

impl StatsBatch {
    /// Lane `l` takes sums `s` about `origin`; lanes beyond [`BATCH`] are
    /// ignored.
    #[inline]
    pub fn set(&mut self, l: usize, s: &CellStats, origin: Vector2<f64>) {
        if l >= BATCH {
            return;
        }
        // Fewer than MIN_POINTS points give no distribution: as 0 points.
        self.n[l] = if s.count >= MIN_POINTS {
            s.points()
        } else {
            0.0
        };
        self.sx[l] = s.sum.x;
        self.sy[l] = s.sum.y;
        self.s00[l] = s.scatter[(0, 0)];
        self.s01[l] = s.scatter[(0, 1)];
        self.s10[l] = s.scatter[(1, 0)];
        self.s11[l] = s.scatter[(1, 1)];
        self.ox[l] = origin.x;
        self.oy[l] = origin.y;
    }
}

/// The distributions of a [`StatsBatch`] (see [`gaussians`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct GaussBatch {
    mx: [f64; BATCH],
    my: [f64; BATCH],
    i00: [f64; BATCH],
    i01: [f64; BATCH],
    i10: [f64; BATCH],
    i11: [f64; BATCH],
    nx: [f64; BATCH],
    ny: [f64; BATCH],
    ok: [bool; BATCH],
}

impl GaussBatch {
    /// Lane `l`'s distribution, `None` where [`Gaussian::from_stats`] gives
    /// none.
    #[inline]
    pub fn get(&self, l: usize) -> Option<Gaussian> {
        if !*self.ok.get(l)? {
            return None;
        }
        Some(Gaussian {
            mean: Vector2::new(self.mx[l], self.my[l]),
            inverse: Matrix2::new(self.i00[l], self.i01[l], self.i10[l], self.i11[l]),
            normal: Vector2::new(self.nx[l], self.ny[l]),
        })
    }
}

/// [`Gaussian::from_stats`] for every lane of `stats` (σ floor
/// `sigma_floor` \[m\], expansion `k`), into `out`.
#[multiversion(targets(
    "x86_64+avx512f+avx512dq+avx512vl+avx2+fma+avx",
    "x86_64+avx2+fma+avx",
    "aarch64+neon"
))]
pub fn gaussians(stats: &StatsBatch, sigma_floor: f64, k: f64, out: &mut GaussBatch) {
    let floor = sigma_floor * sigma_floor;
    for l in 0..BATCH {
        let n = stats.n[l];
        // eq. (7), CellStats::mean_and_covariance: q = m / M, Σ = (S − q mᵀ) / M.
        let (sx, sy) = (stats.sx[l], stats.sy[l]);
        let (qx, qy) = (sx / n, sy / n);
        let c00 = (stats.s00[l] - qx * sx) / n;
        let c01 = (stats.s01[l] - qx * sy) / n;
        let c10 = (stats.s10[l] - qy * sx) / n;
        let c11 = (stats.s11[l] - qy * sy) / n;
        let off = 0.5 * (c01 + c10);
        // crate::cell::symmetric_eigen2 of the symmetrised Σ.
        let (a, b, c) = (c00, 0.5 * (off + off), c11);
        let mid = 0.5 * (a + c);
        let rad = (0.25 * (a - c) * (a - c) + b * b).sqrt();
        let t = a - c;
        let r = 2.0 * rad;
        let (wx, wy) = if b.is_sign_negative() {
            (-2.0 * b, t - r)
        } else {
            (2.0 * b, r - t)
        };
        let ahead = t >= 0.0;
        let dx = if ahead { t + r } else { wx };
        let dy = if ahead { 2.0 * b } else { wy };
        let norm = (dx * dx + dy * dy).sqrt();
        let round = norm == 0.0;
        let v1x = if round { 1.0 } else { dx / norm };
        let v1y = if round { 0.0 } else { dy / norm };
        // Gaussian::from_moments: regularised, expanded by k (eq. 8).
        let l1 = (mid + rad).max(floor);
        let l2 = (mid - rad).max(EIGEN_RATIO * l1).max(floor);
        let (e1, e2) = (k * l1, k * l2);
        let (v2x, v2y) = (-v1y, v1x);
        let i00 = v1x * v1x / e1 + v2x * v2x / e2;
        let i01 = v1x * v1y / e1 + v2x * v2y / e2;
        let i10 = v1y * v1x / e1 + v2y * v2x / e2;
        let i11 = v1y * v1y / e1 + v2y * v2y / e2;
        let finite = i00.is_finite() && i01.is_finite() && i10.is_finite() && i11.is_finite();
        out.ok[l] = n >= MIN_POINTS as f64 && finite;
        out.mx[l] = stats.ox[l] + qx;
        out.my[l] = stats.oy[l] + qy;
        out.i00[l] = i00;
        out.i01[l] = i01;
        out.i10[l] = i10;
        out.i11[l] = i11;
        out.nx[l] = v2x;
        out.ny[l] = v2y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Every lane is [`Gaussian::from_stats`] to the bit: spread, collinear
    /// and coincident points, both eigenvector cases and signs, too few
    /// points, and σ floors and expansions so extreme that there is no
    /// finite distribution.
    #[test]
    fn lanes_give_the_bits_of_from_stats() {
        let mut rng = StdRng::seed_from_u64(21);
        let mut cases = Vec::new();
        for i in 0..3000 {
            let mut s = CellStats::default();
            let pts = [0, 1, 2, 3, 4, 7, 30][i % 7];
            let angle: f64 = rng.random_range(-3.2..3.2);
            for _ in 0..pts {
                let along: f64 = rng.random_range(-0.01..0.01);
                let across: f64 = match i % 5 {
                    0 => 0.0,
                    1 => rng.random_range(-1e-9..1e-9),
                    _ => rng.random_range(-0.004..0.004),
                };
                let p = if i % 11 == 0 {
                    Vector2::new(0.003, -0.002)
                } else {
                    Vector2::new(
                        along * angle.cos() - across * angle.sin(),
                        along * angle.sin() + across * angle.cos(),
                    )
                };
                s.add_point(p);
            }
            let origin = Vector2::new(rng.random_range(-50.0..50.0), rng.random_range(-50.0..50.0));
            let (floor, k) = match i % 13 {
                0 => (1e-200, 1e-200),
                1 => (0.0, 1.0),
                _ => (rng.random_range(0.001..0.03), rng.random_range(1.0..40.0)),
            };
            cases.push((s, origin, floor, k));
        }
        let mut kept = 0;
        for group in cases.chunks(BATCH) {
            // One floor and k per batch, as the store uses them.
            let (floor, k) = (group[0].2, group[0].3);
            let mut batch = StatsBatch::default();
            for (l, (s, o, _, _)) in group.iter().enumerate() {
                batch.set(l, s, *o);
            }
            let mut out = GaussBatch::default();
            gaussians(&batch, floor, k, &mut out);
            for (l, (s, o, _, _)) in group.iter().enumerate() {
                let want = Gaussian::from_stats(s, *o, floor, k);
                let got = out.get(l);
                kept += usize::from(want.is_some());
                let bits = |g: Option<Gaussian>| {
                    g.map(|g| {
                        [g.mean.x, g.mean.y, g.normal.x, g.normal.y]
                            .into_iter()
                            .chain(g.inverse.iter().copied())
                            .map(f64::to_bits)
                            .collect::<Vec<_>>()
                    })
                };
                assert_eq!(bits(got), bits(want), "{s:?} {o} {floor} {k}");
            }
        }
        assert!(kept > 1000 && kept < 2800, "{kept}");
    }
}
