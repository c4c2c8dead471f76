//! The coarser level of a coarse-to-fine stage as a quadratic model.
//!
//! Stage `l` of a pyramid match minimises `−(E_l + E_{l+1})`
//! (`crate::matcher::LEVEL_WINDOW`): the coarser level keeps the wall-scale
//! structure that sparse fine cells lack. It starts where stage `l + 1`
//! ended, at an optimum of `E_{l+1} + E_{l+2}`, and moves from there by a
//! fraction of a coarse cell, over which `E_{l+1}` is smooth. Instead of
//! scoring every point on level `l + 1` again at each trial pose, the stage
//! uses the second-order expansion of eq. (1)'s score there (the same
//! expansion Newton's method makes, eq. 3):
//!
//! `f_{l+1}(p₀ + d) ≈ f₀ + gᵀd + ½ dᵀ|H|d`, with `f = −E`,
//!
//! where `g` and `H` are the gradient and Hessian of eq. (4)–(5) at the
//! stage's start `p₀` and `|H|` has `H`'s eigenvalues replaced by their
//! absolute values (as the solver's step, `crate::solver`): the model is
//! convex, so it cannot pull the pose away along a direction of negative
//! curvature. This halves the passes over the scan of every stage after the
//! first; the final pose's score and Hessian are then recomputed exactly
//! (see `crate::matcher`).

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::score::ScoreTerms;
use crate::se2::Pose2;

/// `f₀ + gᵀd + ½ dᵀ|H|d` about a pose (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadraticModel {
    at: Pose2,
    score: f64,
    gradient: Vector3<f64>,
    hessian: Matrix3<f64>,
    matched: usize,
}

impl QuadraticModel {
    /// The model of the terms `terms` (with derivatives) computed at `at`.
    pub fn new(at: Pose2, terms: &ScoreTerms) -> Self {
        Self {
            at,
            score: terms.score,
            gradient: terms.gradient,
            hessian: absolute(&terms.hessian),
            matched: terms.matched,
        }
    }

    /// The pose the model is expanded about.
    pub fn at(&self) -> Pose2 {
        self.at
    }

    /// The modelled score `E`, gradient and Hessian of `−E` at `pose`; the
    /// matched count is the one at the expansion pose.
    pub fn terms(&self, pose: Pose2) -> ScoreTerms {
        let d = Vector3::new(
            pose.x - self.at.x,
            pose.y - self.at.y,
            pose.theta - self.at.theta,
        );
        let hd = self.hessian * d;
        ScoreTerms {
            score: self.score - self.gradient.dot(&d) - 0.5 * d.dot(&hd),
            gradient: self.gradient + hd,
            hessian: self.hessian,
            matched: self.matched,
        }
    }
}

/// `|H|`: `H` with its eigenvalues replaced by their absolute values.
fn absolute(h: &Matrix3<f64>) -> Matrix3<f64> {
    // Positive definite (the usual case at the end of a stage): |H| = H. A
    // non-finite matrix is kept as it is (no eigen-decomposition of it; the
    // solver stops on such terms anyway).
    if !h.iter().all(|v| v.is_finite()) || h.cholesky().is_some() {
        return *h;
    }
    let eig = SymmetricEigen::new(*h);
    let abs = eig.eigenvectors
        * Matrix3::from_diagonal(&eig.eigenvalues.map(f64::abs))
        * eig.eigenvectors.transpose();
    // Exactly symmetric, like the accumulated Hessians.
    (abs + abs.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    fn terms(hessian: Matrix3<f64>) -> ScoreTerms {
        ScoreTerms {
            score: 5.0,
            gradient: Vector3::new(0.5, -1.0, 2.0),
            hessian,
            matched: 7,
        }
    }

    #[test]
    fn exact_at_the_expansion_pose() {
        let h = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        let p0 = Pose2::new(1.0, 2.0, 0.3);
        let m = QuadraticModel::new(p0, &terms(h));
        let t = m.terms(p0);
        assert_eq!(t.score, 5.0);
        assert_eq!(t.gradient, Vector3::new(0.5, -1.0, 2.0));
        assert!((t.hessian - h).abs().max() < 1e-12);
        assert_eq!(t.matched, 7);
    }

    #[test]
    fn reproduces_a_quadratic_and_its_derivatives() {
        // f(d) = f0 + g.d + 1/2 d.H d for a positive definite H: the model is
        // that function; its gradient against central differences.
        let h = Matrix3::new(4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0);
        let p0 = Pose2::new(1.0, 2.0, 0.3);
        let m = QuadraticModel::new(p0, &terms(h));
        let d = Vector3::new(0.01, -0.02, 0.005);
        let p = Pose2::new(p0.x + d.x, p0.y + d.y, p0.theta + d.z);
        let f = |p: Pose2| -m.terms(p).score;
        let g = Vector3::new(0.5, -1.0, 2.0);
        assert!((f(p) - (-5.0 + g.dot(&d) + 0.5 * d.dot(&(h * d)))).abs() < 1e-12);
        let e = 1e-6;
        for i in 0..3 {
            let mut a = [p.x, p.y, p.theta];
            let mut b = a;
            a[i] += e;
            b[i] -= e;
            let fd =
                (f(Pose2::new(a[0], a[1], a[2])) - f(Pose2::new(b[0], b[1], b[2]))) / (2.0 * e);
            assert!((fd - m.terms(p).gradient[i]).abs() < 1e-7, "{i}");
        }
    }

    #[test]
    fn negative_curvature_is_flipped() {
        let h = Matrix3::from_diagonal(&Vector3::new(2.0, -3.0, 1.0));
        let m = QuadraticModel::new(Pose2::identity(), &terms(h));
        let t = m.terms(Pose2::identity());
        assert!(
            (t.hessian - Matrix3::from_diagonal(&Vector3::new(2.0, 3.0, 1.0)))
                .abs()
                .max()
                < 1e-12
        );
    }
}
