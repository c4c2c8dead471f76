//! `MatchOptions::parallel`: the same pose on 1 or 2 threads, from rayon's
//! global pool or a pool of the caller's, the one-thread result to within
//! rounding, and below `PARALLEL_MIN_POINTS` the one-thread result itself.

mod common;

use ndt_core::{MatchOptions, NdtGrid, Pose2};

fn setup() -> (NdtGrid, Vec<[f64; 2]>, Pose2, Pose2) {
    setup_with(17000)
}

/// The room's grid and a scan of `points` points taken at the truth, with
/// its guess.
fn setup_with(points: usize) -> (NdtGrid, Vec<[f64; 2]>, Pose2, Pose2) {
    let walls = common::room();
    let mut grid = NdtGrid::new(0.02).unwrap();
    for (i, p) in [(0.0, 0.0, 0.0), (0.3, 0.2, 1.0), (-0.4, -0.3, 2.5)]
        .iter()
        .enumerate()
    {
        let pose = Pose2::new(p.0, p.1, p.2);
        grid.insert(&common::scan(&walls, pose, 2000, 4.0, 0.01, i as u64), pose)
            .unwrap();
    }
    let truth = Pose2::new(0.1, -0.05, 0.3);
    let scan = common::scan(&walls, truth, points, 4.0, 0.01, 9);
    let guess = Pose2::new(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.02);
    (grid, scan, guess, truth)
}

#[test]
fn parallel_matches_do_not_depend_on_the_thread_count_and_agree_with_one_thread() {
    let (grid, scan, guess, truth) = setup();
    assert!(scan.len() >= ndt_core::matcher::PARALLEL_MIN_POINTS);
    let parallel = MatchOptions {
        parallel: true,
        ..MatchOptions::default()
    };
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| grid.match_scan(&scan, guess, &parallel).unwrap())
    };
    let (one, two) = (on(1), on(2));
    assert_eq!(one, two);
    // From a thread outside any pool the match moves onto the global pool
    // (crate::matcher's `match_checked`): the same chunks, the same sum.
    let global = grid.match_scan(&scan, guess, &parallel).unwrap();
    assert_eq!(global, one);
    let serial = grid
        .match_scan(&scan, guess, &MatchOptions::default())
        .unwrap();
    for (a, b) in [
        (one.pose.x, serial.pose.x),
        (one.pose.y, serial.pose.y),
        (one.pose.theta, serial.pose.theta),
    ] {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    assert!((one.score - serial.score).abs() < 1e-9 * serial.score);
    assert!((one.pose.x - truth.x).abs() < 0.01 && (one.pose.y - truth.y).abs() < 0.01);
}

#[test]
fn a_scan_below_the_parallel_threshold_is_matched_on_one_thread_bit_for_bit() {
    let below = ndt_core::matcher::PARALLEL_MIN_POINTS - 1;
    let (grid, scan, guess, truth) = setup_with(below);
    assert_eq!(scan.len(), below);
    let serial = grid
        .match_scan(&scan, guess, &MatchOptions::default())
        .unwrap();
    let parallel = MatchOptions {
        parallel: true,
        ..MatchOptions::default()
    };
    assert_eq!(grid.match_scan(&scan, guess, &parallel).unwrap(), serial);
    assert!((serial.pose.x - truth.x).abs() < 0.01 && (serial.pose.y - truth.y).abs() < 0.01);
}

#[test]
fn a_scan_at_the_parallel_threshold_is_split_and_agrees_with_one_thread() {
    let at = ndt_core::matcher::PARALLEL_MIN_POINTS;
    let (grid, scan, guess, truth) = setup_with(at);
    assert_eq!(scan.len(), at);
    let parallel = MatchOptions {
        parallel: true,
        ..MatchOptions::default()
    };
    let split = grid.match_scan(&scan, guess, &parallel).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    assert_eq!(
        pool.install(|| grid.match_scan(&scan, guess, &parallel).unwrap()),
        split
    );
    let serial = grid
        .match_scan(&scan, guess, &MatchOptions::default())
        .unwrap();
    assert!((split.pose.x - serial.pose.x).abs() < 1e-9);
    assert!((split.pose.y - serial.pose.y).abs() < 1e-9);
    assert!((split.pose.theta - serial.pose.theta).abs() < 1e-9);
    assert!((split.pose.x - truth.x).abs() < 0.01 && (split.pose.y - truth.y).abs() < 0.01);
}
