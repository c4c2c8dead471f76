//! Helpers shared by the crate's unit tests.

use nalgebra::{Matrix3, Vector3};
use rand::rngs::StdRng;
use rand::Rng;

/// A symmetric 3 × 3 matrix with `eigenvalues` along random orthogonal
/// directions (exactly symmetric, like the accumulated Hessians).
pub(crate) fn random_symmetric(rng: &mut StdRng, eigenvalues: [f64; 3]) -> Matrix3<f64> {
    let q = nalgebra::Rotation3::from_euler_angles(
        rng.random_range(-3.0..3.0),
        rng.random_range(-1.5..1.5),
        rng.random_range(-3.0..3.0),
    );
    let m =
        q.matrix() * Matrix3::from_diagonal(&Vector3::from(eigenvalues)) * q.matrix().transpose();
    (m + m.transpose()) * 0.5
}
