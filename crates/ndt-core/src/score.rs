//! The NDT score of eq. (1) and its analytic gradient and Hessian (eq. 3–5),
//! accumulated point by point. The solver minimises `f(p) = −E(p)`.

use nalgebra::{Matrix3, Vector2, Vector3};

use crate::cell::Gaussian;

/// How much of the score's Taylor expansion to accumulate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Order {
    /// `E` only (line search).
    Value,
    /// `E`, `∇f` and `∇²f` (Newton step).
    Derivatives,
}

/// Accumulated `E(p)` (eq. 1) with the gradient `g` and Hessian `H` of
/// `f = −E` with respect to `p = (tx, ty, θ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScoreTerms {
    /// `E(p) = Σᵢ exp(−½ dᵢᵀ Σᵢ⁻¹ dᵢ)` over paired points (eq. 1).
    pub score: f64,
    /// `g = ∇(−E)` \[1/m, 1/m, 1/rad\].
    pub gradient: Vector3<f64>,
    /// `H = ∇²(−E)`.
    pub hessian: Matrix3<f64>,
    /// Points that had a reference distribution.
    pub matched: usize,
}

impl Default for ScoreTerms {
    fn default() -> Self {
        Self {
            score: 0.0,
            gradient: Vector3::zeros(),
            hessian: Matrix3::zeros(),
            matched: 0,
        }
    }
}

impl ScoreTerms {
    /// Adds `other`'s score, gradient and Hessian (terms of other points, or
    /// of other pyramid levels); `matched` is the caller's to combine.
    #[inline]
    pub fn add_terms(&mut self, other: &ScoreTerms) {
        self.score += other.score;
        self.gradient += other.gradient;
        self.hessian += other.hessian;
    }

    /// Adds point `x` (scan frame) mapped to `xw = R(θ) x + t` (eq. 2) and
    /// paired with `dist` (the caller counts matched points: a point may be
    /// paired with several distributions); see [`Accumulator::add`].
    #[inline]
    pub fn add(
        &mut self,
        x: Vector2<f64>,
        xw: Vector2<f64>,
        sin_cos: (f64, f64),
        dist: &Gaussian,
        order: Order,
    ) {
        let mut acc = Accumulator::from(*self);
        acc.add(x, xw, sin_cos, dist, 1.0, order);
        *self = acc.finish();
    }
}

/// [`ScoreTerms`] being accumulated over a scan: the Hessian's 6 distinct
/// entries only (it is symmetric), mirrored by [`Accumulator::finish`]. Each
/// entry is computed by the same expression as the full matrix would be, so
/// the result is the same to the bit.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Accumulator {
    /// `E(p)` so far.
    pub score: f64,
    gradient: [f64; 3],
    /// `H₀₀, H₀₁, H₀₂, H₁₁, H₁₂, H₂₂`.
    hessian: [f64; 6],
    /// Points that had a reference distribution.
    pub matched: usize,
}

impl From<ScoreTerms> for Accumulator {
    fn from(t: ScoreTerms) -> Self {
        let h = &t.hessian;
        Self {
            score: t.score,
            gradient: [t.gradient.x, t.gradient.y, t.gradient.z],
            hessian: [
                h[(0, 0)],
                h[(0, 1)],
                h[(0, 2)],
                h[(1, 1)],
                h[(1, 2)],
                h[(2, 2)],
            ],
            matched: t.matched,
        }
    }
}

impl Accumulator {
    /// The accumulated terms, the Hessian mirrored.
    pub fn finish(&self) -> ScoreTerms {
        let h = &self.hessian;
        ScoreTerms {
            score: self.score,
            gradient: Vector3::new(self.gradient[0], self.gradient[1], self.gradient[2]),
            hessian: Matrix3::new(h[0], h[1], h[2], h[1], h[3], h[4], h[2], h[4], h[5]),
            matched: self.matched,
        }
    }

    /// Adds point `x` (scan frame) mapped to `xw = R(θ) x + t` (eq. 2) and
    /// paired with `dist`, standing for `weight` scan points (a centroid of
    /// [`crate::reduce`]; 1 for a point: then the terms are the same to the
    /// bit as unweighted ones). `(sin θ, cos θ)` are passed in so they are
    /// computed once per pose, not per point.
    ///
    /// With `d = x' − q`, `C = Σ⁻¹`, `s = exp(−½ dᵀ C d)`,
    /// `J = ∂x'/∂p = [[1, 0, a], [0, 1, b]]`, `a = −x sinθ − y cosθ`,
    /// `b = x cosθ − y sinθ`:
    /// - `gₖ += s · dᵀ C Jₖ` (eq. 4 for `f = −E`),
    /// - `Hₖₗ += s · (−(dᵀ C Jₖ)(dᵀ C Jₗ) + Jₗᵀ C Jₖ + dᵀ C ∂²x'/∂pₖ∂pₗ)` (eq. 5),
    ///   where only `∂²x'/∂θ² = (−x cosθ + y sinθ, −x sinθ − y cosθ)` is non-zero.
    #[inline]
    pub fn add(
        &mut self,
        x: Vector2<f64>,
        xw: Vector2<f64>,
        sin_cos: (f64, f64),
        dist: &Gaussian,
        weight: f64,
        order: Order,
    ) {
        let d = xw - dist.mean;
        let c = &dist.inverse;
        let (c00, c01, c11) = (c[(0, 0)], c[(0, 1)], c[(1, 1)]);
        let cd0 = c00 * d.x + c01 * d.y;
        let cd1 = c01 * d.x + c11 * d.y;
        let e = d.x * cd0 + d.y * cd1;
        // eq. (1): one point's contribution.
        let s = (-0.5 * e).exp();
        // A point so far out that its term underflows adds nothing (0 · ∞
        // in the derivatives would be NaN with extreme options); an e of NaN
        // (∞ − ∞ from a huge inverse covariance) likewise. For every other
        // point this changes no bit: the skipped terms are exact zeros.
        if s.is_nan() || s <= 0.0 {
            return;
        }
        let s = weight * s;
        self.score += s;
        if order == Order::Value {
            return;
        }
        let (sn, cs) = sin_cos;
        let a = -x.x * sn - x.y * cs;
        let b = x.x * cs - x.y * sn;
        // u_k = dᵀ C J_k
        let u = [cd0, cd1, cd0 * a + cd1 * b];
        for (g, uk) in self.gradient.iter_mut().zip(u) {
            *g += uk * s;
        }
        // J_lᵀ C J_k
        let m02 = c00 * a + c01 * b;
        let m12 = c01 * a + c11 * b;
        let m22 = a * m02 + b * m12;
        // dᵀ C ∂²x'/∂θ²
        let second = cd0 * (-x.x * cs + x.y * sn) + cd1 * (-x.x * sn - x.y * cs);
        let jcj = [c00, c01, m02, c11, m12, m22 + second];
        let h = &mut self.hessian;
        h[0] += (jcj[0] - u[0] * u[0]) * s;
        h[1] += (jcj[1] - u[0] * u[1]) * s;
        h[2] += (jcj[2] - u[0] * u[2]) * s;
        h[3] += (jcj[3] - u[1] * u[1]) * s;
        h[4] += (jcj[4] - u[1] * u[2]) * s;
        h[5] += (jcj[5] - u[2] * u[2]) * s;
    }
}
