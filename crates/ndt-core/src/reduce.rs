//! Weighted point reduction for the coarse stages of the pyramid match.
//!
//! On a pyramid level with cells of `c` metres, scan points a fraction of `c`
//! apart pair with the same distribution and move its score in the same way:
//! a run of consecutive points inside one voxel is replaced by their centroid
//! with the run's length as weight (eq. 1 with `wᵢ exp(−½ dᵢᵀ Σ⁻¹ dᵢ)`, the
//! centroid's `d` standing for its points'). Only consecutive points merge:
//! a laser scan is ordered by angle, so a wall's points come in runs, and the
//! reduction is one pass without hashing. The fine stage always uses every
//! point, so the final pose keeps the fine grid's resolution.

use nalgebra::Vector2;

use crate::key::CellKey;

/// Points with weights: `points[i]` stands for `weights[i]` scan points.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Weighted {
    /// Centroids (scan frame) \[m\].
    pub points: Vec<[f64; 2]>,
    /// Number of scan points each centroid stands for.
    pub weights: Vec<f64>,
}

impl Weighted {
    /// Number of weighted points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// `true` when there are none.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// Merges runs of consecutive `points` that fall into the same square voxel
/// of side `voxel` \[m\] (voxels aligned with the scan frame's origin) into
/// their centroid, weighted by the run length. `voxel ≤ 0` (or not finite)
/// keeps every point with weight 1.
pub fn voxel_runs(points: &[[f64; 2]], voxel: f64) -> Weighted {
    let mut out = Weighted {
        points: Vec::with_capacity(points.len()),
        weights: Vec::with_capacity(points.len()),
    };
    if !(voxel.is_finite() && voxel > 0.0) {
        out.points.extend_from_slice(points);
        out.weights.resize(points.len(), 1.0);
        return out;
    }
    let inv = 1.0 / voxel;
    let index = |p: &[f64; 2]| CellKey::of(Vector2::new(p[0], p[1]), inv);
    let mut run: Option<(Option<CellKey>, [f64; 2], f64)> = None;
    for p in points {
        let key = index(p);
        match &mut run {
            Some((k, sum, n)) if *k == key => {
                sum[0] += p[0];
                sum[1] += p[1];
                *n += 1.0;
            }
            _ => {
                if let Some((_, sum, n)) = run.take() {
                    out.points.push([sum[0] / n, sum[1] / n]);
                    out.weights.push(n);
                }
                run = Some((key, *p, 1.0));
            }
        }
    }
    if let Some((_, sum, n)) = run {
        out.points.push([sum[0] / n, sum[1] / n]);
        out.weights.push(n);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_in_one_voxel_become_their_weighted_centroid() {
        let pts = [
            [0.01, 0.01],
            [0.03, 0.02],
            [0.05, 0.00], // same 10 cm voxel: a run of 3
            [0.15, 0.01], // next voxel
            [0.02, 0.02], // back in the first voxel: a new run
        ];
        let w = voxel_runs(&pts, 0.1);
        assert_eq!(w.weights, vec![3.0, 1.0, 1.0]);
        assert!((w.points[0][0] - 0.03).abs() < 1e-15);
        assert!((w.points[0][1] - 0.01).abs() < 1e-15);
        assert_eq!(w.points[1], [0.15, 0.01]);
        assert_eq!(w.points[2], [0.02, 0.02]);
        let total: f64 = w.weights.iter().sum();
        assert_eq!(total, pts.len() as f64);
    }

    #[test]
    fn no_voxel_keeps_every_point() {
        let pts = [[1.0, 2.0], [1.0, 2.0]];
        for v in [0.0, -1.0, f64::NAN] {
            let w = voxel_runs(&pts, v);
            assert_eq!(w.points, pts.to_vec());
            assert_eq!(w.weights, vec![1.0, 1.0]);
        }
    }
}
