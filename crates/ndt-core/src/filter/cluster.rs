//! §V-B(1) "Edge of object", steps a-1…a-4, applied to every new scan before
//! it reaches the map:
//!
//! - a-1: cluster the scan ([`clusters`]) and select the small clusters
//!   ([`is_small`]);
//! - a-2: the centre of mass of a small cluster ([`centre_of_mass`]);
//! - a-3: drop its points behind the centre of mass ([`behind_com`]): the
//!   mixed returns at an object's edges land *behind* it (Fig. 7a);
//! - a-4: convert the rest to cells and keep only the forefront cell
//!   ([`forefront_cell`]).

use std::ops::Range;

use nalgebra::Vector2;

use crate::filter::Beam;
use crate::key::CellKey;

/// §V step a-1: splits the valid beams (in beam order) into clusters of
/// consecutive points. Beams `i` and `i + 1` belong to one cluster when their
/// points are at most `gap + spacing_factor · r · δ` apart \[m\], with `r` the
/// smaller of the two ranges and `δ` the angular step between adjacent beams
/// (the angle between the two beams divided by how many beam indices apart
/// they are): the second term keeps a far wall, whose points are farther
/// apart, in one cluster. Invalid beams between two points do not split them.
///
/// Returns index ranges into `beams`, covering it in order.
pub fn clusters(beams: &[Beam], gap: f64, spacing_factor: f64) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..beams.len() {
        let (a, b) = (&beams[i - 1], &beams[i]);
        let apart = b.index.saturating_sub(a.index).max(1) as f64;
        let step = (b.angle - a.angle).abs() / apart;
        let limit = gap + spacing_factor * a.range.min(b.range) * step;
        if (b.local - a.local).norm() > limit {
            out.push(start..i);
            start = i;
        }
    }
    if !beams.is_empty() {
        out.push(start..beams.len());
    }
    out
}

/// §V step a-1, "select the cluster with small number": a cluster is a
/// small (sub-grid scale) object when its lateral extent — the spread of its
/// points across the direction from the sensor to their centre of mass —
/// is at most `max_size` \[m\]. The radial spread is ignored on purpose: mixed
/// returns stretch a thin object along the beam, not across it.
pub fn is_small(cluster: &[Beam], max_size: f64) -> bool {
    lateral_extent(cluster) <= max_size
}

/// Spread \[m\] of the points across the bearing of their centre of mass
/// (0 for a single point).
pub fn lateral_extent(cluster: &[Beam]) -> f64 {
    let com = centre_of_mass(cluster);
    let norm = com.norm();
    if cluster.len() < 2 || norm == 0.0 {
        return 0.0;
    }
    let across = Vector2::new(-com.y, com.x) / norm;
    let (lo, hi) = cluster
        .iter()
        .map(|b| b.local.dot(&across))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    hi - lo
}

/// §V step a-2: the centre of mass of a cluster's points, sensor frame \[m\]
/// (the origin for an empty cluster).
pub fn centre_of_mass(cluster: &[Beam]) -> Vector2<f64> {
    if cluster.is_empty() {
        return Vector2::zeros();
    }
    cluster.iter().map(|b| b.local).sum::<Vector2<f64>>() / cluster.len() as f64
}

/// §V step a-3: `true` for each point that lies behind the centre of mass
/// `com` (sensor frame): farther than `com` along the bearing of `com` by
/// more than `margin` \[m\] (plus 1 nm against round-off). Measuring along the
/// bearing rather than by range keeps a cluster whose points lie at one
/// range whole (their mean lies inside the arc, nearer than any of them) and
/// never drops every point: the projections average exactly to `|com|`.
pub fn behind_com(cluster: &[Beam], com: Vector2<f64>, margin: f64) -> Vec<bool> {
    let norm = com.norm();
    if norm == 0.0 {
        return vec![false; cluster.len()];
    }
    let bearing = com / norm;
    let limit = norm + margin + 1e-9;
    cluster
        .iter()
        .map(|b| b.local.dot(&bearing) > limit)
        .collect()
}

/// §V step a-4: the forefront cell of a cluster: the cell (of size `1 /
/// inv_cell_size` m) holding the centre of mass of the points for which
/// `keep` is `true` — after a-3 these are the front part of the object — or,
/// when no kept point lies in that cell, the cell of the kept point nearest
/// to it. `None` when no point is kept.
///
/// Taking the cell of the single nearest point instead would follow the
/// range noise: with σ = 5 mm the nearest of ten points lies 1–2σ in front
/// of the surface, often in the cell in front of it, and a different cell
/// each scan.
pub fn forefront_cell(cluster: &[Beam], keep: &[bool], inv_cell_size: f64) -> Option<CellKey> {
    let kept: Vec<&Beam> = cluster
        .iter()
        .zip(keep)
        .filter(|(_, &k)| k)
        .map(|(b, _)| b)
        .collect();
    if kept.is_empty() {
        return None;
    }
    let com = kept.iter().map(|b| b.world).sum::<Vector2<f64>>() / kept.len() as f64;
    let key = CellKey::of(com, inv_cell_size)?;
    if kept
        .iter()
        .any(|b| CellKey::of(b.world, inv_cell_size) == Some(key))
    {
        return Some(key);
    }
    kept.iter()
        .min_by(|a, b| (a.world - com).norm().total_cmp(&(b.world - com).norm()))
        .and_then(|b| CellKey::of(b.world, inv_cell_size))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::Pose2;

    /// Beams at 0.36° steps from `first`, with the given ranges (0 = invalid).
    fn beams(first: usize, ranges: &[f64]) -> Vec<Beam> {
        let step = 0.36f64.to_radians();
        ranges
            .iter()
            .enumerate()
            .filter(|(_, &r)| r > 0.0)
            .map(|(i, &r)| Beam::new(first + i, r, (first + i) as f64 * step, Pose2::identity()))
            .collect()
    }

    #[test]
    fn a1_splits_at_range_jumps_but_not_at_dropouts() {
        // A wall at 2 m, a stick at 1.2 m (3 beams), the wall again with one
        // dropout (0) inside.
        let b = beams(0, &[2.0, 2.0, 2.0, 1.2, 1.2, 1.21, 2.0, 0.0, 2.0, 2.0]);
        let c = clusters(&b, 0.05, 2.0);
        assert_eq!(c, vec![0..3, 3..6, 6..9]);
        assert!(!is_small(&b[0..3], 0.01));
        assert!(is_small(&b[3..6], 0.05));
        // Lateral extent of 3 beams at 1.2 m: 2 steps of 7.5 mm.
        let w = lateral_extent(&b[3..6]);
        assert!((w - 2.0 * 1.2 * 0.36f64.to_radians()).abs() < 2e-4, "{w}");
        assert!(clusters(&[], 0.05, 2.0).is_empty());
    }

    #[test]
    fn a1_far_wall_stays_one_cluster() {
        // At 4 m adjacent points are 2.5 cm apart; at 60° incidence 5 cm.
        let r: Vec<f64> = (0..20).map(|i| 4.0 + 0.04 * f64::from(i)).collect();
        assert_eq!(clusters(&beams(0, &r), 0.05, 2.0), vec![0..20]);
    }

    #[test]
    fn a2_a3_a4_keep_only_the_front_of_a_small_cluster() {
        // A stick at 1 m with two mixed returns 3 cm and 5 cm behind it.
        let b = beams(100, &[1.05, 1.0, 1.0, 1.002, 1.03]);
        let com = centre_of_mass(&b);
        assert!((com.norm() - 1.0162).abs() < 1e-3);
        let behind = behind_com(&b, com, 0.0);
        assert_eq!(behind, vec![true, false, false, false, true]);
        let keep: Vec<bool> = behind.iter().map(|x| !x).collect();
        let front = forefront_cell(&b, &keep, 50.0).unwrap();
        // The kept points' centre of mass lies in their cell.
        let com_kept = (b[1].world + b[2].world + b[3].world) / 3.0;
        assert_eq!(front, CellKey::of(com_kept, 50.0).unwrap());
        assert_eq!(front, CellKey::of(b[2].world, 50.0).unwrap());
        assert_eq!(forefront_cell(&b, &[false; 5], 50.0), None);
    }

    #[test]
    fn a3_never_drops_a_whole_cluster() {
        // Five points at exactly 0.41 m: their mean lies 0.01 mm nearer than
        // any of them, so by range all five would be behind it; along its
        // bearing only the middle three are (the projections average to it).
        let b = beams(0, &[0.41; 5]);
        let com = centre_of_mass(&b);
        assert!(b.iter().all(|p| p.range > com.norm()));
        assert_eq!(
            behind_com(&b, com, 0.0),
            vec![false, true, true, true, false]
        );
        assert_eq!(behind_com(&b, com, 0.001), vec![false; 5]);
        let one = beams(7, &[1.234]);
        assert_eq!(behind_com(&one, centre_of_mass(&one), 0.0), vec![false]);
    }

    #[test]
    fn a4_forefront_cell_does_not_follow_one_noisy_point() {
        // Four points of one surface at ~1.006 m; one reads 9 mm short and
        // falls into the cell in front (x < 1.00).
        let b = beams(0, &[1.006, 1.008, 0.997, 1.007]);
        let front = forefront_cell(&b, &[true; 4], 50.0).unwrap();
        assert_eq!(front, CellKey { ix: 50, iy: 0 });
        assert_eq!(CellKey::of(b[2].world, 50.0).unwrap().ix, 49);
    }
}
