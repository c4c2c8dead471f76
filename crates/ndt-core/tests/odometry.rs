//! The scan-to-map odometry loop: priors, tracking, memory bound, bad input,
//! the gate of the rotational multi-start.

mod common;

use ndt_core::ranges::points_from_ranges;
use ndt_core::{Mapper, MapperOptions, NdtError, NdtGrid, Odometry, OdometryConfig, Pose2};
/// Ranges of a beam fan at `pose` inside the square `[-2, 2]²`.
fn square_scan(pose: Pose2, beams: usize) -> (Vec<f64>, Vec<f64>) {
    let angles: Vec<f64> = (0..beams)
        .map(|i| -1.5 + 3.0 * i as f64 / (beams - 1) as f64)
        .collect();
    let ranges = angles
        .iter()
        .map(|a| {
            let (s, c) = (pose.theta + a).sin_cos();
            let tx = if c > 0.0 {
                (2.0 - pose.x) / c
            } else {
                (-2.0 - pose.x) / c
            };
            let ty = if s > 0.0 {
                (2.0 - pose.y) / s
            } else {
                (-2.0 - pose.y) / s
            };
            tx.min(ty)
        })
        .collect();
    (ranges, angles)
}

#[test]
fn prediction_follows_odometry_then_constant_velocity() {
    let config = OdometryConfig {
        insert_distance: 100.0,
        insert_angle: 10.0,
        ..OdometryConfig::default()
    };
    let mut odo = Odometry::new(config).unwrap();
    // No valid beam: every pose is the prediction.
    let (r, a) = (vec![0.0; 3], vec![0.0, 0.1, 0.2]);
    let o0 = Pose2::new(1.0, 2.0, 0.5);
    let s0 = odo.step(&r, &a, Some(o0)).unwrap();
    assert_eq!(s0.pose, o0);
    let o1 = o0.compose(Pose2::new(0.1, 0.0, 0.05));
    let s1 = odo.step(&r, &a, Some(o1)).unwrap();
    assert!((s1.pose.x - o1.x).abs() < 1e-12 && (s1.pose.theta - o1.theta).abs() < 1e-12);
    let s2 = odo.step(&r, &a, None).unwrap();
    let expected = o1.compose(Pose2::new(0.1, 0.0, 0.05));
    assert!((s2.pose.x - expected.x).abs() < 1e-12);
    assert!((s2.pose.y - expected.y).abs() < 1e-12);
    assert_eq!(odo.poses().len(), 3);
    assert_eq!(odo.insertions(), 0);
}

#[test]
fn tracks_a_moving_sensor_and_bounds_the_map() {
    let config = OdometryConfig {
        map_window: 3,
        insert_distance: 0.05,
        ..OdometryConfig::default()
    };
    let mut odo = Odometry::new(config).unwrap();
    let mut max_cells = 0;
    for i in 0..40 {
        let t = f64::from(i);
        let truth = Pose2::new(0.02 * t, 0.01 * t, 0.01 * t);
        let (r, a) = square_scan(truth, 361);
        // No odometry: the constant-velocity prior, corrected by matching.
        let out = odo.step(&r, &a, None).unwrap();
        let d = truth.between(out.pose);
        assert!(d.x.hypot(d.y) < 0.01, "scan {i}: {:?}", out.pose);
        assert!(d.theta.abs() < 0.005, "scan {i}: {:?}", out.pose);
        max_cells = max_cells.max(odo.grid().len());
    }
    assert!(odo.insertions() >= 10);
    assert!(max_cells <= 3 * 361);
}

#[test]
fn the_matching_grid_takes_the_scans_its_own_policy_picks() {
    // Scans added to the map every 5 cm; the matching grid takes one when
    // 12 cm from the last it took. No windows, so nothing leaves either map.
    let config = OdometryConfig {
        map_window: 0,
        insert_distance: 0.05,
        insert_angle: 10.0,
        match_insert_distance: 0.12,
        match_insert_angle: 10.0,
        match_map_window: 0,
        ..OdometryConfig::default()
    };
    let mut odo = Odometry::new(config).unwrap();
    let mut expected = NdtGrid::new(config.cell_size).unwrap();
    let (mut taken, mut last_taken): (u64, Option<Pose2>) = (0, None);
    for i in 0..40 {
        let t = f64::from(i);
        let truth = Pose2::new(0.02 * t, 0.01 * t, 0.01 * t);
        let (r, a) = square_scan(truth, 361);
        let out = odo.step(&r, &a, None).unwrap();
        let takes = last_taken.is_none_or(|at| {
            let d = at.between(out.pose);
            d.x.hypot(d.y) >= 0.12 || d.theta.abs() >= 10.0
        });
        if takes {
            let points = points_from_ranges(&r, &a, config.min_range, config.max_range).unwrap();
            expected.insert(&points, out.pose).unwrap();
            (taken, last_taken) = (taken + 1, Some(out.pose));
        }
    }
    assert!(odo.insertions() >= 10, "{}", odo.insertions());
    assert_eq!(odo.grid_insertions(), taken);
    assert!(taken >= 4 && taken < odo.insertions(), "{taken}");
    // The matching grid holds exactly the scans it took, sums bit for bit.
    let grid = odo.grid();
    assert_eq!(grid.len(), expected.len());
    for key in expected.keys() {
        assert_eq!(grid.stats(key), expected.stats(key), "{key:?}");
    }
    // The mapper took the other added scans too: its grid has cells the
    // matching grid lacks.
    let mapper = odo.mapper().unwrap();
    let mapped = mapper.grid();
    assert!(mapped.keys().any(|k| grid.stats(k).is_none()));
}

#[test]
fn bad_input_leaves_the_loop_unchanged() {
    let mut odo = Odometry::new(OdometryConfig::default()).unwrap();
    let (r, a) = square_scan(Pose2::identity(), 90);
    odo.step(&r, &a, None).unwrap();
    let cells = odo.grid().len();
    assert!(odo.step(&r, &a[1..], None).is_err());
    let bad = Pose2 {
        x: f64::NAN,
        y: 0.0,
        theta: 0.0,
    };
    assert!(matches!(
        odo.step(&r, &a, Some(bad)),
        Err(NdtError::NonFinite { what: "odom", .. })
    ));
    assert_eq!(odo.poses().len(), 1);
    assert_eq!(odo.grid().len(), cells);
    let config = OdometryConfig {
        min_match_ratio: 1.5,
        ..OdometryConfig::default()
    };
    assert!(Odometry::new(config).is_err());
}

#[test]
fn mapper_behind_the_loop_equals_the_mapper_in_line() {
    let run = |background_mapper: bool| {
        let config = OdometryConfig {
            map_window: 3,
            insert_distance: 0.03,
            background_mapper,
            ..OdometryConfig::default()
        };
        let mut odo = Odometry::new(config).unwrap();
        let mut snapshots = Vec::new();
        let mut copy = None;
        for i in 0..30 {
            let t = f64::from(i);
            let truth = Pose2::new(0.02 * t, 0.01 * t, 0.01 * t);
            let (r, a) = square_scan(truth, 361);
            odo.step(&r, &a, None).unwrap();
            // Bad input is refused before the queued mapper changes.
            assert!(odo.update_map(&r, &a[1..], truth).is_err());
            if i % 7 == 0 {
                // Views nest (also on one thread) and agree.
                let (first, second) = (odo.mapper().unwrap(), odo.mapper().unwrap());
                assert_eq!(first.grid().len(), second.grid().len());
                snapshots.push(first.to_bytes().unwrap());
            }
            if i == 12 {
                copy = Some(odo.clone());
            }
        }
        // A clone taken mid-run goes on by itself, from the same mapper.
        let mut copy = copy.unwrap();
        let (r, a) = square_scan(Pose2::new(0.3, 0.1, 0.1), 361);
        copy.update_map(&r, &a, Pose2::new(0.3, 0.1, 0.1)).unwrap();
        snapshots.push(copy.mapper().unwrap().to_bytes().unwrap());
        snapshots.push(odo.mapper().unwrap().to_bytes().unwrap());
        let counts = odo.mapper().unwrap().removal_counts();
        (odo.poses().to_vec(), snapshots, counts)
    };
    let (inline, behind) = (run(false), run(true));
    assert!(inline.1.len() == 7 && inline.1.iter().all(|b| !b.is_empty()));
    assert_eq!(inline.0, behind.0);
    assert_eq!(inline.1, behind.1);
    assert_eq!(inline.2, behind.2);
}

/// Scans of the walk through the square in the map tests below.
const WALK_SCANS: u32 = 24;
/// The scan after which a scan is handed to the map alone (`update_map`).
const HANDED_OVER: u32 = 17;

/// Pose `i` of that walk: 2 cm, 1 cm and 0.01 rad a scan.
fn walk(i: u32) -> Pose2 {
    let t = f64::from(i);
    Pose2::new(0.02 * t, 0.01 * t, 0.01 * t)
}

/// The scan handed to the map alone, with its pose: 97 beams, angles the
/// loop has not seen.
fn handed_over() -> (Pose2, (Vec<f64>, Vec<f64>)) {
    let at = Pose2::new(0.3, 0.1, 0.1);
    (at, square_scan(at, 97))
}

/// The loop hands its mapper the beams' kept sines and cosines (one per beam
/// for the whole run) instead of a sine and cosine per beam and scan: the
/// mapper must be the same, bit for bit, as one fed the same scans at the
/// loop's poses through `Mapper::insert_scan`, also when the angles change
/// mid-run (the kept directions are then renewed) and for a scan handed to
/// the map alone (`update_map`, whose angles the loop has not seen).
#[test]
fn the_loops_mapper_equals_a_mapper_fed_the_same_scans() {
    let config = OdometryConfig {
        insert_distance: 0.03,
        ..OdometryConfig::default()
    };
    let mut odo = Odometry::new(config).unwrap();
    let options = MapperOptions {
        min_range: config.min_range,
        max_range: config.max_range,
        ..config.mapper
    };
    let mut mapper = Mapper::new(config.cell_size, options).unwrap();
    for i in 0..WALK_SCANS {
        let beams = if i < 12 { 361 } else { 181 };
        let (r, a) = square_scan(walk(i), beams);
        let step = odo.step(&r, &a, None).unwrap();
        if step.inserted {
            mapper.insert_scan(&r, &a, step.pose).unwrap();
        }
        if i == HANDED_OVER {
            let (at, (r, a)) = handed_over();
            odo.update_map(&r, &a, at).unwrap();
            mapper.insert_scan(&r, &a, at).unwrap();
        }
    }
    assert!(odo.insertions() > 10, "{}", odo.insertions());
    assert_eq!(
        odo.mapper().unwrap().to_bytes().unwrap(),
        mapper.to_bytes().unwrap()
    );
}

/// Ranges and angles of a 361-beam, 180° scan of the room of the shared
/// fixtures at `pose` (5 mm range noise).
fn room_scan(pose: Pose2, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let points = common::scan(
        &common::room(),
        pose,
        361,
        std::f64::consts::PI,
        0.005,
        seed,
    );
    let ranges = points.iter().map(|p| p[0].hypot(p[1])).collect();
    let angles = points.iter().map(|p| p[1].atan2(p[0])).collect();
    (ranges, angles)
}

/// A loop over a steady run in the room whose odometry turns wrong by
/// `error` rad at scan 14 (priors never compared); per step the pose, whether
/// the multi-start ran, and the true pose.
fn run_with_bad_turn(gate: f64, rotation_search: f64, error: f64) -> Vec<(Pose2, bool, Pose2)> {
    let config = OdometryConfig {
        coarse_rotation_gate: gate,
        prior_gap_distance: f64::INFINITY,
        prior_gap_angle: f64::INFINITY,
        insert_distance: 0.05,
        matcher: ndt_core::MatchOptions {
            rotation_search,
            ..OdometryConfig::default().matcher
        },
        ..OdometryConfig::default()
    };
    let mut odo = Odometry::new(config).unwrap();
    (0..18u32)
        .map(|i| {
            let t = f64::from(i);
            let truth = Pose2::new(0.02 * t, 0.01 * t, 0.01 * t);
            let (r, a) = room_scan(truth, u64::from(i));
            let odom = if i == 14 {
                Pose2::new(truth.x, truth.y, truth.theta + error)
            } else {
                truth
            };
            let out = odo.step(&r, &a, Some(odom)).unwrap();
            (out.pose, out.multi_start, truth)
        })
        .collect()
}

fn close(a: Pose2, b: Pose2) -> bool {
    let d = a.between(b);
    d.x.hypot(d.y) < 0.01 && d.theta.abs() < 0.005
}

#[test]
fn the_multi_start_runs_only_when_a_match_looks_poor() {
    // A 1 rad odometry error (a wrong reading at scan 14 spoils the
    // increments into scans 14 and 15), which Newton alone does not undo in
    // this room, and a multi-start that reaches it.
    let (error, search) = (1.0, 1.0);
    let off = run_with_bad_turn(f64::INFINITY, 0.0, error);
    assert!(!close(off[14].0, off[14].2), "{:?}", off[14]);
    assert!(off.iter().all(|s| !s.1));
    // On every scan: every match (from the second scan) ran it; all found.
    let always = run_with_bad_turn(f64::INFINITY, search, error);
    assert!(always[1..].iter().all(|s| s.1));
    assert!(always.iter().all(|s| close(s.0, s.2)), "{always:?}");
    // Gated: the first 8 accepted matches ran it, then only the two poor
    // ones, and every pose is found as with the multi-start everywhere.
    let gated = run_with_bad_turn(0.8, search, error);
    let ran: Vec<usize> = (0..gated.len()).filter(|&i| gated[i].1).collect();
    assert_eq!(ran, vec![1, 2, 3, 4, 5, 6, 7, 8, 14, 15]);
    assert!(gated.iter().all(|s| close(s.0, s.2)), "{gated:?}");
}

#[test]
fn the_gate_must_be_a_fraction_of_at_least_zero() {
    for bad in [f64::NAN, -0.1] {
        let config = OdometryConfig {
            coarse_rotation_gate: bad,
            ..OdometryConfig::default()
        };
        let err = Odometry::new(config).unwrap_err().to_string();
        assert!(
            err.starts_with("coarse_rotation_gate: expected a fraction >= 0"),
            "{err}"
        );
    }
}

/// Ranges and angles of a 181-beam, 180° scan (1° beams, as a SICK) of an
/// 8 m × 5 m hall with a pillar, from `pose` (5 mm range noise): most
/// points lie alone in their 2 cm cell, with no neighbour to fuse with (a
/// scan matched against one other pairs about a quarter of its points).
fn hall_scan(pose: Pose2, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut walls = vec![
        ([-4.0, -2.5], [4.0, -2.5]),
        ([4.0, -2.5], [4.0, 2.5]),
        ([4.0, 2.5], [-4.0, 2.5]),
        ([-4.0, 2.5], [-4.0, -2.5]),
    ];
    walls.extend([
        ([3.0, 1.0], [3.6, 1.0]),
        ([3.6, 1.0], [3.6, 1.6]),
        ([3.6, 1.6], [3.0, 1.6]),
        ([3.0, 1.6], [3.0, 1.0]),
    ]);
    let points = common::scan(&walls, pose, 181, std::f64::consts::PI, 0.005, seed);
    let ranges = points.iter().map(|p| p[0].hypot(p[1])).collect();
    let angles = points.iter().map(|p| p[1].atan2(p[0])).collect();
    (ranges, angles)
}

#[test]
fn a_young_sparse_map_accepts_converged_matches_so_the_loop_starts() {
    let run = |bootstrap_insertions: usize, skip_levels: u32| {
        let d = OdometryConfig::default();
        let config = OdometryConfig {
            bootstrap_insertions,
            matcher: ndt_core::MatchOptions {
                skip_levels,
                ..d.matcher
            },
            ..d
        };
        let mut odo = Odometry::new(config).unwrap();
        let mut worst: f64 = 0.0;
        for i in 0..40u32 {
            let truth = Pose2::new(0.03 * f64::from(i), 0.0, 0.0);
            let (r, a) = hall_scan(truth, u64::from(i));
            let out = odo.step(&r, &a, None).unwrap();
            let d = truth.between(out.pose);
            worst = worst.max(d.x.hypot(d.y));
        }
        (worst, odo.insertions())
    };
    // Matching on every level, without the rule the first match is refused,
    // the pose stays at the origin and no second scan is ever inserted.
    let (stuck_error, stuck_insertions) = run(0, 0);
    assert_eq!(stuck_insertions, 1);
    assert!(stuck_error > 1.0, "{stuck_error}");
    // With the rule, and with the loop's default levels (the 4 cm one passed
    // over, whose first match is accepted without it here), the loop starts.
    let skip = OdometryConfig::default().matcher.skip_levels;
    for (bootstrap, skip_levels) in [(2, 0), (2, skip), (0, skip)] {
        let (error, insertions) = run(bootstrap, skip_levels);
        assert!(insertions >= 10, "{insertions}");
        assert!(error < 0.02, "{error}");
    }
}

/// `build_map: false` (poses only): the same poses and matching grid, bit for
/// bit, as the default loop on the same scans (one of them handed over by
/// `update_map`), no insertion into a map, and the map asked for is an error.
#[test]
fn a_loop_without_a_map_gives_the_same_poses_and_grid() {
    let with_map = OdometryConfig {
        insert_distance: 0.03,
        ..OdometryConfig::default()
    };
    let mut full = Odometry::new(with_map).unwrap();
    let mut bare = Odometry::new(OdometryConfig {
        build_map: false,
        ..with_map
    })
    .unwrap();
    for i in 0..WALK_SCANS {
        let (r, a) = square_scan(walk(i), 181);
        let (s_full, s_bare) = (
            full.step(&r, &a, None).unwrap(),
            bare.step(&r, &a, None).unwrap(),
        );
        assert_eq!(s_full.pose, s_bare.pose, "scan {i}");
        assert!(!s_bare.inserted);
        if i == HANDED_OVER {
            let (at, (r, a)) = handed_over();
            full.update_map(&r, &a, at).unwrap();
            bare.update_map(&r, &a, at).unwrap();
        }
    }
    assert_eq!(full.poses(), bare.poses());
    assert!(full.insertions() > 10, "{}", full.insertions());
    assert_eq!(bare.insertions(), 0);
    assert_eq!(full.grid_insertions(), bare.grid_insertions());
    assert_eq!(
        full.grid().to_bytes().unwrap(),
        bare.grid().to_bytes().unwrap()
    );
    assert!(full.mapper().is_ok());
    let err = bare.mapper().err().unwrap();
    assert_eq!(err, NdtError::NoMap);
    assert_eq!(
        err.to_string(),
        "this odometry builds no map (build_map is off): it keeps the poses and the grid it \
         matches against only"
    );
}

#[test]
fn a_filtered_map_needs_a_map() {
    let err = Odometry::new(OdometryConfig {
        build_map: false,
        match_filtered_map: true,
        ..OdometryConfig::default()
    })
    .err()
    .unwrap();
    assert_eq!(
        err.to_string(),
        "match_filtered_map: cannot be on with build_map off: the loop would match against a \
         map it does not build"
    );
}
