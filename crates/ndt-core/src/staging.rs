//! The points of a scan to insert in map coordinates (eq. 2) with their
//! fine cells (§III-B), in vector lanes: [`NdtGrid::insert`] and the
//! odometry loop stage every scan they add, and the staging's scalar loop
//! (a conversion instruction per coordinate, which does not vectorise) took
//! about a twelfth of an insert.
//!
//! [`NdtGrid::insert`]: crate::grid::NdtGrid::insert

use multiversion::multiversion;
use nalgebra::Vector2;

use crate::key::CellKey;
use crate::se2::Pose2;

/// Points a pass takes at once.
const LANES: usize = 8;

/// One point: its map coordinates (eq. 2) and its cell
/// ([`CellKey::of_flagged_in_lanes`]), and whether its cell exists.
#[inline(always)]
fn stage_point(
    p: [f64; 2],
    pose: Pose2,
    sin_cos: (f64, f64),
    inv: f64,
) -> ((CellKey, Vector2<f64>), bool) {
    let w = pose.transform_with(sin_cos, Vector2::new(p[0], p[1]));
    let (key, ok) = CellKey::of_flagged_in_lanes(w, inv);
    ((key, w), ok)
}

/// Appends to `out` every point of `points` seen from `pose` (`sin_cos`:
/// of its angle) in map coordinates with its cell on a lattice of
/// `1 / inv` m, in order; `true` when every cell exists (else the cells of
/// the points beyond the lattice are meaningless).
#[multiversion(targets(
    "x86_64+avx512f+avx512dq+avx512vl+avx2+fma+avx",
    "x86_64+avx2+fma+avx",
    "aarch64+neon"
))]
pub(crate) fn stage_points(
    points: &[[f64; 2]],
    pose: Pose2,
    sin_cos: (f64, f64),
    inv: f64,
    out: &mut Vec<(CellKey, Vector2<f64>)>,
) -> bool {
    out.reserve(points.len());
    let mut all = true;
    let chunks = points.chunks_exact(LANES);
    let rest = chunks.remainder();
    for chunk in chunks {
        let mut staged = [(CellKey { ix: 0, iy: 0 }, Vector2::zeros()); LANES];
        let mut ok = [false; LANES];
        for ((p, s), o) in chunk.iter().zip(&mut staged).zip(&mut ok) {
            (*s, *o) = stage_point(*p, pose, sin_cos, inv);
        }
        all &= ok.iter().all(|&o| o);
        out.extend_from_slice(&staged);
    }
    for p in rest {
        let (s, o) = stage_point(*p, pose, sin_cos, inv);
        all &= o;
        out.push(s);
    }
    all
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::se2::Pose2;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Every point and cell, bit for bit, as the scalar eq. (2) and
    /// `CellKey::of` give them, for scans of every length around the lanes'
    /// width, near cell borders and at the lattice's edge (where a point
    /// beyond it makes the result `false`).
    #[test]
    fn points_and_cells_equal_the_scalar_ones() {
        let mut rng = StdRng::seed_from_u64(9);
        for n in 0..40 {
            for scale in [0.01, 3.0, 2.2e7] {
                let pose = Pose2::new(
                    rng.random_range(-5.0..5.0),
                    rng.random_range(-5.0..5.0),
                    rng.random_range(-3.2..3.2),
                );
                let inv: f64 = 1.0 / 0.02;
                // Some on cell borders exactly.
                let coordinate = |rng: &mut StdRng| {
                    let v: f64 = rng.random_range(-scale..scale);
                    if rng.random_bool(0.2) {
                        (v * inv).round() / inv
                    } else {
                        v
                    }
                };
                let points: Vec<[f64; 2]> = (0..n)
                    .map(|_| [coordinate(&mut rng), coordinate(&mut rng)])
                    .collect();
                let (s, c) = pose.theta.sin_cos();
                let mut out = Vec::new();
                let all = stage_points(&points, pose, (s, c), inv, &mut out);
                let mut every = true;
                assert_eq!(out.len(), points.len());
                for (p, (key, w)) in points.iter().zip(&out) {
                    let want = pose.transform_with((s, c), Vector2::new(p[0], p[1]));
                    assert_eq!(w.x.to_bits(), want.x.to_bits());
                    assert_eq!(w.y.to_bits(), want.y.to_bits());
                    match CellKey::of(want, inv) {
                        Some(k) => assert_eq!(*key, k, "{p:?}"),
                        None => every = false,
                    }
                }
                assert_eq!(all, every, "n {n} scale {scale}");
            }
        }
    }
}
