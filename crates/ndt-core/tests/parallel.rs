//! `MatchOptions::parallel`: the same pose on 1 or 2 threads, from rayon's
//! global pool or a pool of the caller's, the one-thread result to within
//! rounding, and below `PARALLEL_MIN_POINTS` the one-thread result itself.

mod common;

use ndt_core::{MatchOptions, MatchResult, NdtGrid, Pose2};

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

/// The default options with [`MatchOptions::parallel`].
fn parallel() -> MatchOptions {
    MatchOptions {
        parallel: true,
        ..MatchOptions::default()
    }
}

/// `scan` matched with `options` on a pool of the caller's of `threads`
/// threads.
fn on_pool(
    grid: &NdtGrid,
    scan: &[[f64; 2]],
    guess: Pose2,
    options: &MatchOptions,
    threads: usize,
) -> MatchResult {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| grid.match_scan(scan, guess, options).unwrap())
}

/// `a`'s pose within 1e-9 of `b`'s, component by component.
fn assert_same_pose(a: &MatchResult, b: &MatchResult) {
    for (x, y) in [
        (a.pose.x, b.pose.x),
        (a.pose.y, b.pose.y),
        (a.pose.theta, b.pose.theta),
    ] {
        assert!((x - y).abs() < 1e-9, "{x} vs {y}");
    }
}

/// `r`'s position within 1 cm of the truth.
fn assert_near(r: &MatchResult, truth: Pose2) {
    assert!((r.pose.x - truth.x).abs() < 0.01 && (r.pose.y - truth.y).abs() < 0.01);
}

#[test]
fn parallel_matches_do_not_depend_on_the_thread_count_and_agree_with_one_thread() {
    let (grid, scan, guess, truth) = setup();
    assert!(scan.len() >= ndt_core::matcher::PARALLEL_MIN_POINTS);
    let parallel = parallel();
    let one = on_pool(&grid, &scan, guess, &parallel, 1);
    let two = on_pool(&grid, &scan, guess, &parallel, 2);
    assert_eq!(one, two);
    // From a thread outside any pool the match moves onto the global pool
    // (crate::matcher's `match_checked`): the same chunks, the same sum.
    let global = grid.match_scan(&scan, guess, &parallel).unwrap();
    assert_eq!(global, one);
    let serial = grid
        .match_scan(&scan, guess, &MatchOptions::default())
        .unwrap();
    assert_same_pose(&one, &serial);
    assert!((one.score - serial.score).abs() < 1e-9 * serial.score);
    assert_near(&one, truth);
}

#[test]
fn a_scan_below_the_parallel_threshold_is_matched_on_one_thread_bit_for_bit() {
    let below = ndt_core::matcher::PARALLEL_MIN_POINTS - 1;
    let (grid, scan, guess, truth) = setup_with(below);
    assert_eq!(scan.len(), below);
    let serial = grid
        .match_scan(&scan, guess, &MatchOptions::default())
        .unwrap();
    assert_eq!(grid.match_scan(&scan, guess, &parallel()).unwrap(), serial);
    assert_near(&serial, truth);
}

#[test]
fn a_scan_at_the_parallel_threshold_is_split_and_agrees_with_one_thread() {
    let at = ndt_core::matcher::PARALLEL_MIN_POINTS;
    let (grid, scan, guess, truth) = setup_with(at);
    assert_eq!(scan.len(), at);
    let parallel = parallel();
    let split = grid.match_scan(&scan, guess, &parallel).unwrap();
    assert_eq!(on_pool(&grid, &scan, guess, &parallel, 2), split);
    let serial = grid
        .match_scan(&scan, guess, &MatchOptions::default())
        .unwrap();
    assert_same_pose(&split, &serial);
    assert_near(&split, truth);
}

#[test]
fn a_phased_parallel_match_does_not_depend_on_the_pool_it_runs_on() {
    let (grid, scan, guess, truth) = setup_with(ndt_core::matcher::PARALLEL_MIN_POINTS);
    let parallel = parallel();
    let phases = [100.0, 10.0, 1.0];
    // Its phases on one thread of the global pool (crate::matcher's
    // `phased_checked`), against the same on a 1-thread pool of the caller's.
    let global = grid.match_phased(&scan, guess, &parallel, &phases).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one = pool.install(|| grid.match_phased(&scan, guess, &parallel, &phases).unwrap());
    assert_eq!(global, one);
    let serial = grid
        .match_phased(&scan, guess, &MatchOptions::default(), &phases)
        .unwrap();
    assert_same_pose(&global, &serial);
    assert_near(&global, truth);
}
