//! A synthetic scan is recovered from offsets inside the basin.

mod common;

use ndt_core::{MatchOptions, NdtGrid, Pose2};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn dense_map(cell: f64) -> NdtGrid {
    map_with_noise(cell, 0.0)
}

/// [`dense_map`] from scans with range noise σ = `noise` \[m\].
fn map_with_noise(cell: f64, noise: f64) -> NdtGrid {
    let walls = common::room();
    let mut grid = NdtGrid::new(cell).unwrap();
    // A few noise-free scans from nearby poses, as a map is built.
    for (i, p) in [
        (0.0, 0.0, 0.0),
        (0.3, 0.2, 1.0),
        (-0.4, -0.3, 2.5),
        (0.5, -0.5, -1.8),
    ]
    .iter()
    .enumerate()
    {
        let pose = Pose2::new(p.0, p.1, p.2);
        grid.insert(&common::urg_scan(&walls, pose, noise, i as u64), pose)
            .unwrap();
    }
    grid
}

fn recover(cell: f64, max_t: f64, max_r_deg: f64, seed: u64, options: &MatchOptions) {
    let walls = common::room();
    let grid = dense_map(cell);
    let truth = Pose2::new(0.12, -0.08, 0.2);
    let scan = common::urg_scan(&walls, truth, 0.0, 99);
    let mut rng = StdRng::seed_from_u64(seed);
    for _ in 0..20 {
        let guess = Pose2::new(
            truth.x + rng.random_range(-max_t..max_t),
            truth.y + rng.random_range(-max_t..max_t),
            truth.theta + rng.random_range(-max_r_deg..max_r_deg).to_radians(),
        );
        let res = grid.match_scan(&scan, guess, options).unwrap();
        let dt = ((res.pose.x - truth.x).powi(2) + (res.pose.y - truth.y).powi(2)).sqrt();
        let dr = (res.pose.theta - truth.theta).abs().to_degrees();
        assert!(res.converged, "{res:?} from {guess:?}");
        assert!(
            dt < 1e-3,
            "translation error {dt} m from {guess:?} with {options:?}"
        );
        assert!(dr < 0.05, "rotation error {dr}° from {guess:?}");
    }
}

#[test]
fn recovers_synthetic_scan_on_2cm_grid() {
    recover(0.02, 0.05, 1.5, 1, &MatchOptions::default());
}

#[test]
fn recovers_synthetic_scan_on_2cm_grid_with_every_level_scored_exactly() {
    let exact = MatchOptions {
        coarse_model: false,
        ..MatchOptions::default()
    };
    recover(0.02, 0.05, 1.5, 1, &exact);
}

/// With the coarser level modelled (the default), the result's score and
/// Hessian are still the exact ones of both levels at the returned pose: the
/// same as a match with every level scored exactly that starts there and
/// stops at once.
#[test]
fn the_coarse_model_reports_the_exact_score_at_its_pose() {
    let walls = common::room();
    let grid = dense_map(0.02);
    let truth = Pose2::new(0.12, -0.08, 0.2);
    let scan = common::urg_scan(&walls, truth, 0.0, 99);
    let guess = Pose2::new(0.15, -0.05, 0.21);
    let res = grid
        .match_scan(&scan, guess, &MatchOptions::default())
        .unwrap();
    let check = MatchOptions {
        coarse_model: false,
        levels: Some(3),
        rotation_search: 0.0,
        max_iterations: 0,
        ..MatchOptions::default()
    };
    // Levels 2 and 0 (the default skips 4 cm), no iteration: the second
    // stage scores levels 0 and 2 exactly at the start.
    let at = grid.match_scan(&scan, res.pose, &check).unwrap();
    assert_eq!(at.pose, res.pose);
    assert!(
        (at.score - res.score).abs() <= 1e-12 * res.score.abs(),
        "{} vs {}",
        at.score,
        res.score
    );
    assert!((at.hessian - res.hessian).abs().max() <= 1e-12 * res.hessian.abs().max());
}

#[test]
fn recovers_synthetic_scan_on_20cm_grid() {
    // On a coarse grid the default's final stage also sums the 40 cm level,
    // whose expanded cells bias the optimum by ~2 mm: match on the 20 cm level.
    // These scans are noise-free; the default 2 cm σ floor (sized for real
    // range noise) rounds the short wall ends of 20 cm cells into blobs that
    // bias the optimum by ~1.2 mm, so the floor is set to 5 mm here.
    let fine_only = MatchOptions {
        levels: Some(1),
        sigma_floor: 0.005,
        ..MatchOptions::default()
    };
    recover(0.2, 0.08, 3.0, 2, &fine_only);
}

#[test]
fn empty_grid_does_not_converge_and_empty_scan_is_an_error() {
    let grid = NdtGrid::new(0.02).unwrap();
    let res = grid
        .match_scan(&[[1.0, 0.0]], Pose2::identity(), &MatchOptions::default())
        .unwrap();
    assert!(!res.converged);
    assert_eq!(res.num_matched, 0);
    let err = grid
        .match_scan(&[], Pose2::identity(), &MatchOptions::default())
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "points: expected at least one point, got 0"
    );
}

/// The rotational multi-start's gate: from a start close enough for Newton
/// the first stage explains the scan and the turned starts are skipped (the
/// result of no multi-start, bit for bit); from 0.6 rad off it does not, and
/// the multi-start runs (the result of the multi-start always) and finds the
/// pose that Newton alone misses (5 mm range noise, map and scan).
#[test]
fn the_rotation_gate_skips_the_multi_start_only_when_the_first_stage_explains_the_scan() {
    let walls = common::room();
    let grid = map_with_noise(0.02, 0.005);
    let truth = Pose2::new(0.12, -0.08, 0.2);
    let scan = common::urg_scan(&walls, truth, 0.005, 99);
    let with_gate = |rotation_gate: f64, guess: Pose2| {
        let options = MatchOptions {
            rotation_gate,
            ..MatchOptions::default()
        };
        grid.match_scan(&scan, guess, &options).unwrap()
    };
    let found = |p: Pose2| {
        let d = truth.between(p);
        d.x.hypot(d.y) < 5e-3 && d.theta.abs() < 5e-3
    };
    let default_gate = MatchOptions::default().rotation_gate;
    let near = Pose2::new(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.1);
    let (never, gated, always) = (
        with_gate(0.0, near),
        with_gate(default_gate, near),
        with_gate(f64::INFINITY, near),
    );
    assert!(found(gated.pose) && found(always.pose));
    assert_eq!(
        (gated.pose, gated.iterations),
        (never.pose, never.iterations)
    );
    assert!(always.iterations > gated.iterations, "{always:?}");
    let far = Pose2::new(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.6);
    let (never, gated, always) = (
        with_gate(0.0, far),
        with_gate(default_gate, far),
        with_gate(f64::INFINITY, far),
    );
    assert!(!found(never.pose), "{never:?}");
    assert!(found(gated.pose), "{gated:?}");
    assert_eq!(
        (gated.pose, gated.iterations),
        (always.pose, always.iterations)
    );
}

/// `skip_levels` (the default passes over the 4 cm level):
/// a match that skips middle levels still recovers the scan, never builds
/// the skipped levels' distributions, and differs from the full match; the
/// coarsest matched level is matched whatever its bit says; the fine level
/// cannot be skipped.
#[test]
fn skipped_levels_are_passed_over() {
    let with_skip = |skip_levels: u32| MatchOptions {
        skip_levels,
        ..MatchOptions::default()
    };
    recover(0.02, 0.05, 1.5, 7, &with_skip(1 << 1));
    recover(0.02, 0.05, 1.5, 8, &with_skip(1 << 1 | 1 << 3));
    let walls = common::room();
    let truth = Pose2::new(0.12, -0.08, 0.2);
    let scan = common::urg_scan(&walls, truth, 0.0, 99);
    let guess = Pose2::new(0.15, -0.1, 0.22);
    let run = |options: &MatchOptions| {
        let grid = dense_map(0.02);
        let res = grid.match_scan(&scan, guess, options).unwrap();
        (res, grid.heap_bytes())
    };
    let (full, full_bytes) = run(&with_skip(0));
    let (skipped, skipped_bytes) = run(&with_skip(1 << 1));
    // The default skips the 4 cm level.
    let (default, _) = run(&MatchOptions::default());
    assert_eq!(default.pose, skipped.pose);
    assert_ne!(full.pose, skipped.pose);
    // One level's distributions fewer (a 64-byte one per 4 cm cell at least).
    let fours = dense_map(0.02).level(1).map_or(0, |l| l.cells().len());
    assert!(
        full_bytes >= skipped_bytes + 64 * fours,
        "{full_bytes} {skipped_bytes} {fours}"
    );
    // The match has 6 levels: bit 5 (the coarsest) changes nothing.
    let (top, _) = run(&with_skip(1 << 5));
    assert_eq!(
        (top.pose, top.score, top.iterations),
        (full.pose, full.score, full.iterations)
    );
    for bad in [1, 1 << 12] {
        let err = dense_map(0.02)
            .match_scan(&scan, guess, &with_skip(bad))
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            format!(
                "skip_levels: expected a mask of pyramid levels 1 to 11 \
                 (the fine level cannot be skipped), got {bad}"
            )
        );
    }
}
