//! Shared fixtures of the integration tests: a tiny deterministic ray caster
//! over line segments, so scans look like a real laser's.
#![allow(dead_code)]

use ndt_core::{NdtError, NdtGrid, Pose2};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// A wall from `a` to `b` \[m\].
pub type Segment = ([f64; 2], [f64; 2]);

/// A 6 m × 4 m room with an inner box, a pillar-like square and a diagonal wall:
/// enough structure to constrain x, y and θ.
pub fn room() -> Vec<Segment> {
    let mut s = vec![
        ([-3.0, -2.0], [3.0, -2.0]),
        ([3.0, -2.0], [3.0, 2.0]),
        ([3.0, 2.0], [-3.0, 2.0]),
        ([-3.0, 2.0], [-3.0, -2.0]),
        ([1.0, 0.5], [2.0, 1.5]),
    ];
    let square = |cx: f64, cy: f64, h: f64| -> Vec<Segment> {
        vec![
            ([cx - h, cy - h], [cx + h, cy - h]),
            ([cx + h, cy - h], [cx + h, cy + h]),
            ([cx + h, cy + h], [cx - h, cy + h]),
            ([cx - h, cy + h], [cx - h, cy - h]),
        ]
    };
    s.extend(square(-1.5, 0.8, 0.3));
    s.extend(square(0.5, -1.2, 0.15));
    s
}

/// Range along the ray from `o` in direction `(c, s)` to the nearest segment.
fn cast(o: [f64; 2], dir: [f64; 2], walls: &[Segment]) -> Option<f64> {
    let mut best: Option<f64> = None;
    for (a, b) in walls {
        let e = [b[0] - a[0], b[1] - a[1]];
        let den = dir[0] * e[1] - dir[1] * e[0];
        if den.abs() < 1e-12 {
            continue;
        }
        let w = [a[0] - o[0], a[1] - o[1]];
        let t = (w[0] * e[1] - w[1] * e[0]) / den;
        let u = (w[0] * dir[1] - w[1] * dir[0]) / den;
        if t > 1e-9 && (0.0..=1.0).contains(&u) && best.is_none_or(|b| t < b) {
            best = Some(t);
        }
    }
    best
}

/// A scan in the sensor frame from `pose` (`T_map_scan`): `beams` rays over
/// `fov` radians, range noise σ = `noise` metres (seeded).
pub fn scan(
    walls: &[Segment],
    pose: Pose2,
    beams: usize,
    fov: f64,
    noise: f64,
    seed: u64,
) -> Vec<[f64; 2]> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(beams);
    for i in 0..beams {
        let a = -fov / 2.0 + fov * i as f64 / (beams - 1) as f64;
        let wa = pose.theta + a;
        if let Some(r) = cast([pose.x, pose.y], [wa.cos(), wa.sin()], walls) {
            // Box–Muller keeps the dependency list short.
            let u1: f64 = rng.random_range(1e-12..1.0);
            let u2: f64 = rng.random_range(0.0..1.0);
            let n = (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos();
            let r = r + noise * n;
            out.push([r * a.cos(), r * a.sin()]);
        }
    }
    out
}

/// A URG-04LX-like scan (683 beams over 240°).
pub fn urg_scan(walls: &[Segment], pose: Pose2, noise: f64, seed: u64) -> Vec<[f64; 2]> {
    scan(walls, pose, 683, 240f64.to_radians(), noise, seed)
}

/// A scan of [`room`] from `pose` with `beams` beams and 1 cm range noise, as
/// the benches take them: over 240° from 683 beams on (a URG-04LX), else
/// over 180° (a SICK).
pub fn room_scan(beams: usize, pose: Pose2, seed: u64) -> Vec<[f64; 2]> {
    let fov = if beams >= 683 { 240f64 } else { 180f64 };
    scan(&room(), pose, beams, fov.to_radians(), 0.01, seed)
}

/// The 8 poses the benches build their maps of [`room`] from, each with the
/// seed of its scan's noise.
pub fn room_poses() -> impl Iterator<Item = (Pose2, u64)> {
    (0..8u32).map(|i| {
        let a = f64::from(i) * 0.8;
        (Pose2::new(0.3 * a.cos(), 0.2 * a.sin(), a), u64::from(i))
    })
}

/// A grid of `cell` \[m\] holding the [`room_scan`]s of `beams` beams from
/// [`room_poses`]: the map the benches and the profiling examples time on.
pub fn room_map(beams: usize, cell: f64) -> Result<NdtGrid, NdtError> {
    let mut grid = NdtGrid::new(cell)?;
    for (pose, seed) in room_poses() {
        grid.insert(&room_scan(beams, pose, seed), pose)?;
    }
    Ok(grid)
}

/// The pose of the scan the benches time (insert, pyramid update, match), and
/// the scan of `beams` beams seen from it.
pub fn timed_scan(beams: usize) -> (Pose2, Vec<[f64; 2]>) {
    let pose = Pose2::new(0.1, -0.05, 0.3);
    (pose, room_scan(beams, pose, 42))
}

/// The scan the insert benches put into the map before their timed inserts,
/// and its pose.
pub fn before_scan(beams: usize) -> (Pose2, Vec<[f64; 2]>) {
    let pose = Pose2::new(0.05, -0.02, 0.25);
    (pose, room_scan(beams, pose, 43))
}
