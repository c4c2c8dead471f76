//! The geometric information a scan carries about its pose: the point-to-plane
//! information matrix `Σ Jᵢᵀ nᵢ nᵢᵀ Jᵢ`, with `nᵢ` the normal (the direction
//! of least spread, before regularisation: [`crate::cell::Gaussian::normal`])
//! of the distribution point `i` is paired with.
//!
//! Unlike the Hessian of the fine-grid score, it does not count the
//! cell-to-cell texture along a wall as information: a long corridor carries
//! none along its axis, however finely it is gridded.

use nalgebra::{Matrix3, Vector2, Vector3};

use crate::distributions::Distributions;
use crate::se2::Pose2;

/// `A = Σ Jᵢᵀ nᵢ nᵢᵀ Jᵢ` over `(point, distribution)` pairs, in the order
/// `x, y, θ`, with `Jᵢ = ∂x'ᵢ/∂p` of eq. (2) at `pose`.
pub fn point_to_plane_information(
    pairs: impl Iterator<Item = (Vector2<f64>, crate::cell::Gaussian)>,
    pose: Pose2,
) -> Matrix3<f64> {
    let (s, c) = pose.theta.sin_cos();
    let mut a = Matrix3::zeros();
    for (x, g) in pairs {
        let n = g.normal;
        let jt = Vector3::new(
            n.x,
            n.y,
            n.x * (-x.x * s - x.y * c) + n.y * (x.x * c - x.y * s),
        );
        a += jt * jt.transpose();
    }
    a
}

/// The pairs of `points` (scan frame) at `pose` with their own cell's
/// distribution in `dists`.
pub fn own_cell_pairs<'a>(
    dists: &'a Distributions,
    points: &'a [[f64; 2]],
    pose: Pose2,
) -> impl Iterator<Item = (Vector2<f64>, crate::cell::Gaussian)> + 'a {
    let inv = 1.0 / dists.cell_size();
    let mut cursor = dists.cursor();
    let sin_cos = pose.theta.sin_cos();
    points.iter().filter_map(move |p| {
        let x = Vector2::new(p[0], p[1]);
        let key = crate::key::CellKey::of(pose.transform_with(sin_cos, x), inv)?;
        cursor.get(key).map(|g| (x, g))
    })
}
