//! Property tests of issue 6: arbitrary input, finite or not, never panics;
//! every call either succeeds with a consistent map or fails with an
//! [`NdtError`] and changes nothing.
//!
//! - `insert`: arbitrary points and poses; success ⇒ the cells' eq. (6) sums
//!   equal a naive per-point sum; error ⇒ the grid is bit for bit unchanged.
//! - `match_scan`: arbitrary points, guesses and options (extreme values
//!   included); success ⇒ a finite pose and score (never a NaN pose, let
//!   alone with `converged`).
//! - the §V `Mapper`: sequences of random scans with random invalid ranges
//!   (NaN, ±inf, 0, negative, huge) and poses; after each call every grid
//!   cell has a filter record (filter on), the pyramid equals one rebuilt from the fine
//!   cells, and a match on the grid (whose distributions were prepared
//!   incrementally in between) equals the match on that rebuilt grid, bit
//!   for bit; a failed call changes nothing.
//! - `insert_many`: arbitrary batches; the grid the inserts one by one give,
//!   or, when an insert would reject a scan, that scan's error (the first
//!   such) and no change at all; either way consistent with a rebuild.
//! - `remove_cells`: arbitrary keys (present, absent, repeated) remove exactly
//!   the distinct present ones and leave a grid equal to a rebuild.
//! - `Odometry::step`: random scans, odometry and invalid readings; a failed
//!   step changes nothing.
//!
//! Case count: `PROPTEST_CASES` (default 16 per property, a few seconds in
//! CI). The run at scale recorded in BENCHMARK.md ("Reliability (issue 6)"):
//!
//! ```text
//! PROPTEST_CASES=20000 nice cargo test --release -p ndt-core --test properties
//! ```

mod common;

use std::collections::BTreeMap;

use ndt_core::nalgebra::Vector2;
use ndt_core::{
    CellKey, Mapper, MapperOptions, MatchOptions, NdtError, NdtGrid, Odometry, OdometryConfig,
    Pose2,
};
use proptest::prelude::*;
use proptest::test_runner::FileFailurePersistence;

/// Cases per property: `PROPTEST_CASES`, else a CI-sized default.
fn config() -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(16);
    ProptestConfig {
        cases,
        failure_persistence: Some(Box::new(FileFailurePersistence::Off)),
        ..ProptestConfig::default()
    }
}

/// Any `f64`: mostly moderate, often extreme or not finite.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => -5.0..5.0f64,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => prop_oneof![Just(1e300), Just(-1e300), Just(3e7), Just(-2.2e7), Just(1e-300)],
        1 => any::<f64>(),
    ]
}

/// Mostly valid, sometimes wild.
fn mostly(valid: std::ops::Range<f64>) -> impl Strategy<Value = f64> {
    prop_oneof![20 => valid, 1 => wild()]
}

/// Half the time clean points, half the time with a wild value here and there
/// (so that both the success and the error paths are exercised).
fn points(max: usize) -> impl Strategy<Value = Vec<[f64; 2]>> {
    prop_oneof![
        prop::collection::vec([-4.0..4.0f64, -4.0..4.0f64], 0..max),
        prop::collection::vec([mostly(-4.0..4.0), mostly(-4.0..4.0)], 0..max),
    ]
}

fn pose() -> impl Strategy<Value = Pose2> {
    (mostly(-2.0..2.0), mostly(-2.0..2.0), mostly(-4.0..4.0))
        .prop_map(|(x, y, t)| Pose2::new(x, y, t))
}

/// A laser scan: ranges with every kind of invalid reading, angles in beam
/// order (occasionally not finite).
fn scan(max_beams: usize) -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    // Per beam: 1 in 25 NaN/inf/0/negative, 1 in 250 huge (10^9 m and more
    // overflow the grid: an error unless `max_range` skips them).
    let range = prop_oneof![
        240 => 0.05..6.0f64,
        2 => Just(f64::NAN),
        2 => Just(f64::INFINITY),
        2 => Just(f64::NEG_INFINITY),
        2 => Just(0.0),
        2 => -3.0..0.0f64,
        1 => prop_oneof![Just(1e5), Just(1e9), Just(1e300), Just(5e-324)],
    ];
    (
        1..max_beams,
        -3.2..0.0f64,
        0.001..0.05f64,
        prop::collection::vec(range, max_beams),
    )
        .prop_flat_map(|(n, start, step, ranges)| {
            let angles: Vec<f64> = (0..n).map(|i| start + step * i as f64).collect();
            let ranges = ranges[..n].to_vec();
            (Just(ranges), Just(angles), 0..40usize, wild())
        })
        .prop_map(|(ranges, mut angles, spoil, value)| {
            // One beam in 40 scans gets a wild angle.
            if spoil < angles.len() && spoil == 0 {
                angles[0] = value;
            }
            (ranges, angles)
        })
}

/// A grid of the synthetic room seen from two poses.
fn room_grid() -> NdtGrid {
    let mut grid = NdtGrid::new(0.02).unwrap_or_else(|e| panic!("{e}"));
    for (i, p) in [Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.4, -0.2, 1.2)]
        .into_iter()
        .enumerate()
    {
        let s = common::urg_scan(&common::room(), p, 0.005, i as u64);
        grid.insert(&s, p).unwrap_or_else(|e| panic!("{e}"));
    }
    grid
}

/// The naive eq. (6): per cell, count, Σx and Σxxᵀ of the map-frame points.
type Naive = BTreeMap<CellKey, (u64, [f64; 2], [f64; 3])>;

fn naive(pts: &[[f64; 2]], pose: Pose2, cell: f64, into: &mut Naive) {
    for p in pts {
        let w = pose.transform(Vector2::new(p[0], p[1]));
        let Some(k) = CellKey::of(w, 1.0 / cell) else {
            continue;
        };
        let e = into.entry(k).or_insert((0, [0.0; 2], [0.0; 3]));
        e.0 += 1;
        e.1[0] += w.x;
        e.1[1] += w.y;
        e.2[0] += w.x * w.x;
        e.2[1] += w.x * w.y;
        e.2[2] += w.y * w.y;
    }
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-9 * scale.max(1.0)
}

/// The grid rebuilt from its fine cells: the reference every incremental
/// update must equal.
fn rebuilt(grid: &NdtGrid) -> NdtGrid {
    NdtGrid::from_cell_states(grid.cell_size(), &grid.cell_states())
        .unwrap_or_else(|e| panic!("rebuild: {e}"))
}

/// Every pyramid level equals a rebuild's, and matching gives bit-identical
/// results (the incrementally updated distributions equal fresh ones).
fn assert_consistent(grid: &NdtGrid, probe: &[[f64; 2]], at: Pose2) -> Result<(), TestCaseError> {
    let fresh = rebuilt(grid);
    for l in 0..grid.levels() {
        let (a, b) = (grid.level(l), fresh.level(l));
        prop_assert!(a.map(|x| x.cells()) == b.map(|x| x.cells()), "level {l}");
    }
    if !grid.is_empty() && !probe.is_empty() {
        let opts = MatchOptions::default();
        let plain = MatchOptions {
            fuse_minority: false,
            levels: Some(1),
            ..opts
        };
        for o in [opts, plain] {
            let (a, b) = (
                grid.match_scan(probe, at, &o),
                fresh.match_scan(probe, at, &o),
            );
            prop_assert_eq!(a, b);
        }
    }
    Ok(())
}

fn error_is_input(e: &NdtError) -> bool {
    matches!(
        e,
        NdtError::NonFinite { .. }
            | NdtError::CellIndexOverflow { .. }
            | NdtError::Empty { .. }
            | NdtError::LengthMismatch { .. }
            | NdtError::InvalidOption { .. }
    )
}

/// An insert with points beyond the lattice names the first of them, with
/// its map coordinates, and changes nothing (the scan is staged in one pass
/// and checked at its end).
#[test]
fn an_insert_beyond_the_lattice_names_its_first_such_point() {
    let mut grid = NdtGrid::new(0.02).unwrap_or_else(|e| panic!("{e}"));
    let pose = Pose2::new(1.0, -2.0, 0.3);
    let mut pts: Vec<[f64; 2]> = (0..40).map(|i| [0.1 * f64::from(i), 0.5]).collect();
    grid.insert(&pts, pose).unwrap_or_else(|e| panic!("{e}"));
    let before = grid.cell_states();
    pts[17] = [3e7, 0.0];
    pts[29] = [-5e7, 1.0];
    let w = pose.transform(Vector2::new(3e7, 0.0));
    match grid.insert(&pts, pose) {
        Err(NdtError::CellIndexOverflow {
            what: "points",
            index: 17,
            x,
            y,
            ..
        }) => assert_eq!((x, y), (w.x, w.y)),
        other => panic!("{other:?}"),
    }
    assert_eq!(before, grid.cell_states());
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn insert_sums_equal_a_naive_sum_or_nothing_changes(
        batches in prop::collection::vec((points(60), pose()), 1..5),
    ) {
        let cell = 0.02;
        let mut grid = NdtGrid::new(cell).unwrap_or_else(|e| panic!("{e}"));
        let mut want = Naive::new();
        for (pts, p) in &batches {
            let before = grid.cell_states();
            match grid.insert(pts, *p) {
                Ok(_) => naive(pts, *p, cell, &mut want),
                Err(e) => {
                    prop_assert!(error_is_input(&e), "{e}");
                    prop_assert_eq!(&before, &grid.cell_states());
                }
            }
        }
        let got = grid.cells();
        prop_assert_eq!(got.len(), want.len());
        for r in &got {
            let Some((n, s, q)) = want.get(&r.key) else {
                return Err(TestCaseError::fail(format!("extra cell {:?}", r.key)));
            };
            prop_assert_eq!(r.count, *n);
            let scale = s[0].abs() + s[1].abs() + q[0].abs() + q[2].abs();
            prop_assert!(close(r.sum.x, s[0], scale) && close(r.sum.y, s[1], scale));
            prop_assert!(close(r.scatter[(0, 0)], q[0], scale));
            prop_assert!(close(r.scatter[(0, 1)], q[1], scale));
            prop_assert!(close(r.scatter[(1, 1)], q[2], scale));
        }
        assert_consistent(&grid, &[[1.0, 0.5], [-1.0, 0.2], [0.3, 1.9]], Pose2::identity())?;
    }

    #[test]
    fn insert_many_equals_the_inserts_or_changes_nothing(
        batch in prop::collection::vec((points(60), pose()), 0..6),
    ) {
        // The first scan an insert rejects, with its error, on a scratch grid.
        let mut scratch = room_grid();
        let first_error = batch
            .iter()
            .enumerate()
            .find_map(|(i, (pts, p))| scratch.insert(pts, *p).err().map(|e| (i, e)));
        let mut one_by_one = room_grid();
        let mut batched = room_grid();
        // Distributions prepared before the batch, kept up to date by it.
        let probe = [[1.0, 0.5], [-1.0, 0.2], [0.3, 1.9]];
        let _ = batched.match_scan(&probe, Pose2::identity(), &MatchOptions::default());
        let before = batched.cell_states();
        let views: Vec<&[[f64; 2]]> = batch.iter().map(|(pts, _)| pts.as_slice()).collect();
        let poses: Vec<Pose2> = batch.iter().map(|(_, p)| *p).collect();
        match (batched.insert_many(&views, &poses), first_error) {
            (Ok(()), None) => {
                for (pts, p) in &batch {
                    one_by_one.insert(pts, *p).unwrap_or_else(|e| panic!("{e}"));
                }
                prop_assert_eq!(one_by_one.cell_states(), batched.cell_states());
                prop_assert_eq!(one_by_one.key_bounds(), batched.key_bounds());
            }
            (Err(NdtError::InScan { index, error }), Some((i, e))) => {
                prop_assert_eq!(index, i);
                prop_assert_eq!(error.to_string(), e.to_string());
                prop_assert_eq!(&before, &batched.cell_states());
            }
            (got, want) => {
                return Err(TestCaseError::fail(format!("batch {got:?}, inserts {want:?}")));
            }
        }
        assert_consistent(&batched, &probe, Pose2::identity())?;
    }

    // The option strategies are boxed: fourteen unboxed value trees overflow
    // a test thread's 2 MiB stack in a debug build.
    #[test]
    fn match_never_panics_and_never_returns_a_non_finite_pose(
        pts in points(80),
        guess in pose(),
        expansion in prop_oneof![0.5..50.0f64, Just(1e-300), Just(1e300), wild()].boxed(),
        sigma_floor in prop_oneof![0.001..0.05f64, Just(1e-300), Just(1e300), wild()].boxed(),
        shape_cell in prop_oneof![Just(0.0), 0.0..1.0f64, Just(1e300), wild()].boxed(),
        freeze_ratio in prop_oneof![0.0..1.0f64, Just(1.0), wild()].boxed(),
        tol in prop_oneof![1e-6..1e-2f64, Just(1e-300), Just(1e300), wild()].boxed(),
        max_step_cells in prop_oneof![0.5..5.0f64, Just(1e-300), Just(1e300), wild()].boxed(),
        max_step_rotation in prop_oneof![0.01..0.5f64, Just(1e300), wild()].boxed(),
        rotation_search in prop_oneof![0.0..0.5f64, Just(std::f64::consts::PI), wild()].boxed(),
        rotation_gate in prop_oneof![0.0..1.0f64, Just(f64::INFINITY), wild()].boxed(),
        search_radius in prop_oneof![0..4u32, Just(1000u32), Just(1001u32)].boxed(),
        max_iterations in prop_oneof![0..60u32, Just(200u32)].boxed(),
        levels in prop_oneof![Just(None), (0..9u32).prop_map(Some)].boxed(),
        skip_levels in prop_oneof![Just(0u32), 0..64u32, Just(1u32 << 12)].boxed(),
        flags in any::<[bool; 6]>(),
    ) {
        let grid = room_grid();
        let options = MatchOptions {
            expansion,
            sigma_floor,
            shape_cell,
            neighbor_search: flags[0],
            search_radius,
            fuse_minority: flags[1],
            pair_neighbors: flags[2],
            max_iterations,
            translation_tolerance: tol,
            rotation_tolerance: tol,
            max_step_cells,
            max_step_rotation,
            rotation_search,
            rotation_gate,
            freeze_unconstrained: flags[3],
            freeze_ratio,
            levels,
            skip_levels,
            coarse_model: flags[5],
            parallel: flags[4],
        };
        match grid.match_scan(&pts, guess, &options) {
            Ok(r) => {
                let p = r.pose.to_array();
                prop_assert!(p.iter().all(|v| v.is_finite()), "pose {p:?} converged {}", r.converged);
                prop_assert!(r.score.is_finite(), "score {}", r.score);
                prop_assert!(r.num_matched <= pts.len());
            }
            Err(e) => prop_assert!(error_is_input(&e), "{e}"),
        }
        // Score terms and the phased match take the same input.
        if let Err(e) = grid.score_terms(&pts, guess, &options) {
            prop_assert!(error_is_input(&e), "{e}");
        }
        if let Ok(r) = grid.match_phased(&pts, guess, &options, &[expansion, 1.0]) {
            prop_assert!(r.pose.to_array().iter().all(|v| v.is_finite()));
        }
    }

    #[test]
    fn mapper_keeps_grid_and_filter_consistent(
        scans in prop::collection::vec((scan(120), pose()), 1..7),
        flags in any::<[bool; 6]>(),
        check_interval in 1..4u32,
        min_range in prop_oneof![Just(0.0), 0.0..0.5f64],
        max_range in prop_oneof![Just(f64::INFINITY), 1.0..8.0f64],
        removals in prop::collection::vec((-300..300i32, -300..300i32), 0..20),
    ) {
        let options = MapperOptions {
            outlier_filter: flags[0],
            edge_removal: flags[1],
            area1_confirmation: flags[2],
            backshift_rejection: flags[3],
            observation_check: flags[4],
            radial_confirmation: flags[5],
            check_interval,
            min_range,
            max_range,
            ..MapperOptions::default()
        };
        let mut mapper = Mapper::new(0.02, options).unwrap_or_else(|e| panic!("{e}"));
        let probe = common::scan(&common::room(), Pose2::identity(), 90, 3.0, 0.0, 1);
        for (k, ((ranges, angles), p)) in scans.iter().enumerate() {
            let before = (mapper.grid().cell_states(), mapper.filter().scans(), mapper.removal_counts());
            match mapper.insert_scan(ranges, angles, *p) {
                Ok(()) => {}
                Err(e) => {
                    prop_assert!(error_is_input(&e), "{e}");
                    let after = (mapper.grid().cell_states(), mapper.filter().scans(), mapper.removal_counts());
                    prop_assert_eq!(before, after);
                }
            }
            // With the filter on, every cell came through it (the unfiltered
            // map keeps no records).
            if options.outlier_filter {
                for key in mapper.grid().keys() {
                    prop_assert!(mapper.filter().cell_info(key).is_some(), "cell {key:?} has no record");
                }
            }
            for key in mapper.filter().small_cells(mapper.grid()) {
                prop_assert!(mapper.grid().stats(key).is_some());
            }
            if k == 1 {
                let keys: Vec<CellKey> = removals.iter().map(|&(ix, iy)| CellKey { ix, iy }).collect();
                mapper.remove_cells(&keys);
            }
            assert_consistent(mapper.grid(), &probe, Pose2::new(0.01, -0.01, 0.01))?;
        }
        mapper.run_checks();
        assert_consistent(mapper.grid(), &probe, Pose2::identity())?;
    }

    #[test]
    fn remove_cells_removes_exactly_the_distinct_present_keys(
        picks in prop::collection::vec(0..2000usize, 0..60),
        absent in prop::collection::vec((any::<i32>(), any::<i32>()), 0..10),
        prepare in any::<bool>(),
    ) {
        let mut grid = room_grid();
        let probe = common::scan(&common::room(), Pose2::identity(), 90, 3.0, 0.0, 2);
        if prepare {
            // Distributions prepared before the removal are updated by it.
            let _ = grid.match_scan(&probe, Pose2::identity(), &MatchOptions::default());
        }
        let states = grid.cell_states();
        let mut keys: Vec<CellKey> = picks.iter().map(|&i| states[i % states.len()].0).collect();
        keys.extend(absent.iter().map(|&(ix, iy)| CellKey { ix, iy }));
        let distinct: std::collections::BTreeSet<CellKey> =
            keys.iter().copied().filter(|k| grid.stats(*k).is_some()).collect();
        let removed = grid.remove_cells(&keys);
        prop_assert_eq!(removed, distinct.len());
        let left: Vec<_> = states.iter().filter(|(k, _)| !distinct.contains(k)).copied().collect();
        prop_assert_eq!(&grid.cell_states(), &left);
        assert_consistent(&grid, &probe, Pose2::new(0.02, 0.0, -0.01))?;
    }

    #[test]
    fn odometry_steps_never_panic_and_failures_change_nothing(
        steps in prop::collection::vec((scan(90), prop::option::of(pose())), 1..6),
        max_range in prop_oneof![Just(30.0), Just(f64::INFINITY)],
        window in 0..3usize,
    ) {
        let config = OdometryConfig {
            max_range,
            map_window: window,
            rotation_search: 0.05,
            ..OdometryConfig::default()
        };
        let mut odo = Odometry::new(config).unwrap_or_else(|e| panic!("{e}"));
        for ((ranges, angles), odom) in &steps {
            let before = (odo.poses().to_vec(), odo.insertions(), odo.grid().cell_states());
            match odo.step(ranges, angles, *odom) {
                Ok(out) => {
                    prop_assert!(out.pose.to_array().iter().all(|v| v.is_finite()));
                    prop_assert_eq!(odo.poses().len(), before.0.len() + 1);
                }
                Err(e) => {
                    prop_assert!(error_is_input(&e), "{e}");
                    let after = (odo.poses().to_vec(), odo.insertions(), odo.grid().cell_states());
                    prop_assert_eq!(before, after);
                }
            }
        }
    }
}

/// The case the match property found at scale (before the fix: score NaN): a
/// tiny but valid expansion `k` made `k·σ²` subnormal, the inverse covariance
/// infinite and the score NaN.
#[test]
fn a_subnormal_expansion_gives_a_finite_score() {
    let grid = room_grid();
    let options = MatchOptions {
        expansion: 1.2903343324094226e-308,
        sigma_floor: 0.005,
        shape_cell: 0.0,
        neighbor_search: false,
        search_radius: 0,
        fuse_minority: false,
        pair_neighbors: true,
        max_iterations: 0,
        translation_tolerance: 1e-6,
        rotation_tolerance: 1e-6,
        max_step_cells: 0.5,
        max_step_rotation: 0.01,
        rotation_search: 0.0,
        rotation_gate: f64::INFINITY,
        freeze_unconstrained: false,
        freeze_ratio: 0.1,
        levels: None,
        skip_levels: 0,
        coarse_model: true,
        parallel: false,
    };
    let pts = [[-2.3763401613489026, 2.3516387683799254]];
    let r = grid
        .match_scan(&pts, Pose2::new(0.0, 0.0, -1.9098511669164244), &options)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(r.score.is_finite() && r.pose.to_array().iter().all(|v| v.is_finite()));
    for k in [1e-300, 1e-320, 1e300] {
        let o = MatchOptions {
            expansion: k,
            max_iterations: 20,
            ..options
        };
        let r = grid
            .match_scan(
                &common::scan(&common::room(), Pose2::identity(), 90, 3.0, 0.0, 3),
                Pose2::identity(),
                &o,
            )
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(
            r.score.is_finite() && r.pose.to_array().iter().all(|v| v.is_finite()),
            "k = {k}"
        );
    }
}
