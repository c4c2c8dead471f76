//! Rigid motions of the plane, SE(2): the pose `p = (tx, ty, θ)` of eq. (2).

use nalgebra::{Matrix2, Matrix3, Vector2};

use crate::error::{check_finite, Result};

/// A pose `T_map_scan`: maps scan-frame points into the map frame by eq. (2),
/// `x' = R(θ) x + t`. Translation in metres, rotation in radians.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose2 {
    /// Translation along the map's x axis \[m\].
    pub x: f64,
    /// Translation along the map's y axis \[m\].
    pub y: f64,
    /// Rotation \[rad\]; kept wrapped to (−π, π] by the constructors.
    pub theta: f64,
}

/// Wraps an angle to (−π, π] \[rad\]. A NaN or infinite angle is returned
/// as it is, so that the checks that reject it name the value given (an
/// infinite angle wrapped would be NaN).
pub fn wrap_angle(theta: f64) -> f64 {
    if !theta.is_finite() {
        return theta;
    }
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut a = theta.rem_euclid(two_pi);
    if a > std::f64::consts::PI {
        a -= two_pi;
    }
    a
}

impl Pose2 {
    /// A pose with its angle wrapped to (−π, π].
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Self {
            x,
            y,
            theta: wrap_angle(theta),
        }
    }

    /// A pose from `[x, y, θ]`, rejecting non-finite components.
    pub fn try_from_slice(what: &'static str, v: &[f64; 3]) -> Result<Self> {
        check_finite(what, v)?;
        Ok(Self::new(v[0], v[1], v[2]))
    }

    /// The identity motion.
    pub fn identity() -> Self {
        Self::default()
    }

    /// `[x, y, θ]`.
    pub fn to_array(self) -> [f64; 3] {
        [self.x, self.y, self.theta]
    }

    /// Rotation matrix `R(θ)`.
    pub fn rotation(self) -> Matrix2<f64> {
        let (s, c) = self.theta.sin_cos();
        Matrix2::new(c, -s, s, c)
    }

    /// Homogeneous 3×3 matrix of the motion.
    pub fn to_matrix(self) -> Matrix3<f64> {
        let (s, c) = self.theta.sin_cos();
        Matrix3::new(c, -s, self.x, s, c, self.y, 0.0, 0.0, 1.0)
    }

    /// eq. (2): `x' = R(θ) x + t` \[m\].
    #[inline]
    pub fn transform(self, p: Vector2<f64>) -> Vector2<f64> {
        self.transform_with(self.theta.sin_cos(), p)
    }

    /// [`Pose2::transform`] with `(sin θ, cos θ)` computed once by the caller
    /// (loops over a scan).
    #[inline]
    pub fn transform_with(self, (s, c): (f64, f64), p: Vector2<f64>) -> Vector2<f64> {
        Vector2::new(c * p.x - s * p.y + self.x, s * p.x + c * p.y + self.y)
    }

    /// `self ∘ other`: first `other`, then `self` (`T_a_c = T_a_b ∘ T_b_c`).
    pub fn compose(self, other: Pose2) -> Pose2 {
        let t = self.transform(Vector2::new(other.x, other.y));
        Pose2::new(t.x, t.y, self.theta + other.theta)
    }

    /// The inverse motion.
    pub fn inverse(self) -> Pose2 {
        let (s, c) = self.theta.sin_cos();
        Pose2::new(
            -(c * self.x + s * self.y),
            s * self.x - c * self.y,
            -self.theta,
        )
    }

    /// The motion from `self` to `other` expressed in `self`'s frame
    /// (`self⁻¹ ∘ other`), as odometry increments are.
    pub fn between(self, other: Pose2) -> Pose2 {
        self.inverse().compose(other)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn angles_wrap_to_the_half_open_interval_and_non_finite_ones_stay() {
        assert_eq!(wrap_angle(0.5), 0.5);
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert!((wrap_angle(3.0 * PI + 0.25) - (-PI + 0.25)).abs() < 1e-12);
        assert!((wrap_angle(-7.0) - (-7.0 + 2.0 * PI)).abs() < 1e-12);
        assert_eq!(wrap_angle(f64::INFINITY), f64::INFINITY);
        assert_eq!(wrap_angle(f64::NEG_INFINITY), f64::NEG_INFINITY);
        assert!(wrap_angle(f64::NAN).is_nan());
        // So the check of a pose names the value given.
        let err = Pose2::try_from_slice("pose", &[0.0, 0.0, f64::INFINITY]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "pose: expected finite values, got inf at index 2"
        );
    }
}
