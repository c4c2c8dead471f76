//! The §IV-A fixes, the pyramid and the degeneracy flag on constructed cases.

mod common;

use nalgebra::{Matrix2, Vector2};
use ndt_core::cell::{symmetric_eigen2, CellStats};
use ndt_core::distributions::{DistOptions, Distributions};
use ndt_core::neighbor::nearest_in_rings;
use ndt_core::{CellKey, Gaussian, MatchOptions, NdtGrid, Pose2};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn stats(points: &[[f64; 2]], origin: [f64; 2]) -> CellStats {
    let mut s = CellStats::default();
    for p in points {
        s.add_point(Vector2::new(p[0] - origin[0], p[1] - origin[1]));
    }
    s
}

#[test]
fn expansion_multiplies_both_eigenvalues_and_keeps_eigenvectors() {
    // A wall-like cell of 20 cm: spread along a 30° line, thinner across
    // (both above the 1 cm σ floor, so the regularisation leaves the shape alone).
    let pts: Vec<[f64; 2]> = (0..12)
        .map(|i| {
            // Each position along the line twice, once on either side of it.
            let t = -0.08 + 0.032 * f64::from(i / 2);
            let n = if i % 2 == 0 { 0.02 } else { -0.02 };
            let (s, c) = 30f64.to_radians().sin_cos();
            [t * c - n * s, t * s + n * c]
        })
        .collect();
    let s = stats(&pts, [0.0, 0.0]);
    let g1 = Gaussian::from_stats(&s, Vector2::zeros(), 0.01, 1.0).unwrap();
    let g10 = Gaussian::from_stats(&s, Vector2::zeros(), 0.01, 10.0).unwrap();
    let (a1, a2, v) = symmetric_eigen2(&g1.covariance());
    let (b1, b2, w) = symmetric_eigen2(&g10.covariance());
    assert!((b1 / a1 - 10.0).abs() < 1e-9, "{a1} {b1}");
    assert!((b2 / a2 - 10.0).abs() < 1e-9, "{a2} {b2}");
    assert!((v.dot(&w).abs() - 1.0).abs() < 1e-12);
    let angle = v.y.atan2(v.x).to_degrees().rem_euclid(180.0);
    assert!((angle - 30.0).abs() < 1e-6, "{angle}");
    assert_eq!(g1.mean, g10.mean);
}

#[test]
fn small_eigenvalue_is_regularised() {
    // Collinear points: a singular covariance.
    let pts: Vec<[f64; 2]> = (0..5).map(|i| [0.004 * f64::from(i), 0.0]).collect();
    let g = Gaussian::from_stats(&stats(&pts, [0.0, 0.0]), Vector2::zeros(), 0.005, 1.0).unwrap();
    let (l1, l2, _) = symmetric_eigen2(&g.covariance());
    assert!(l2 >= 0.01 * l1 * (1.0 - 1e-12));
    assert!(l2 >= (0.005f64).powi(2) * (1.0 - 1e-12));
}

#[test]
fn two_point_cell_gets_the_fused_distribution() {
    let cell = 0.02;
    let mut grid = NdtGrid::with_levels(cell, 1).unwrap();
    // Cell (0, 0) holds 2 points; its right neighbour (1, 0) 3 points; (0, 1) 1.
    let own = [[0.004, 0.011], [0.015, 0.009]];
    let right = [[0.025, 0.01], [0.031, 0.012], [0.036, 0.008]];
    let up = [[0.012, 0.027]];
    for set in [&own[..], &right[..], &up[..]] {
        grid.insert(set, Pose2::identity()).unwrap();
    }
    let level = grid.level(0).unwrap();
    let fused = Distributions::build(
        level.cells(),
        cell,
        0,
        DistOptions {
            expansion: 1.0,
            fuse_minority: true,
            sigma_floor: 0.005,
            shape_cell: 0.0,
        },
        None,
    );
    let plain = Distributions::build(
        level.cells(),
        cell,
        0,
        DistOptions {
            expansion: 1.0,
            fuse_minority: false,
            sigma_floor: 0.005,
            shape_cell: 0.0,
        },
        None,
    );
    let key = CellKey { ix: 0, iy: 0 };
    assert!(
        plain.get(key).is_none(),
        "2 points form no distribution alone"
    );
    let g = fused.get(key).expect("fused distribution");
    // It is eq. (7) of the summed sums of the 3×3 block: all six points.
    let all: Vec<[f64; 2]> = own.iter().chain(&right).chain(&up).copied().collect();
    let expect =
        Gaussian::from_stats(&stats(&all, [0.0, 0.0]), Vector2::zeros(), 0.005, 1.0).unwrap();
    assert!((g.mean - expect.mean).norm() < 1e-15);
    assert!((g.inverse - expect.inverse).norm() < 1e-6 * expect.inverse.norm());
    // The 1-point cell (0, 1) also fuses (its block holds all six points too).
    assert!(fused.get(CellKey { ix: 0, iy: 1 }).is_some());
    assert!(plain.get(CellKey { ix: 0, iy: 1 }).is_none());
}

#[test]
fn neighbour_search_pairs_a_point_outside_every_cell() {
    let cell = 0.02;
    let mut grid = NdtGrid::with_levels(cell, 1).unwrap();
    let wall: Vec<[f64; 2]> = (0..40).map(|i| [0.001 * f64::from(i), 0.0101]).collect();
    grid.insert(&wall, Pose2::identity()).unwrap();
    let level = grid.level(0).unwrap();
    let d = Distributions::build(
        level.cells(),
        cell,
        0,
        DistOptions {
            expansion: 10.0,
            fuse_minority: true,
            sigma_floor: 0.005,
            shape_cell: 0.0,
        },
        None,
    );
    // A point two cells above the wall: its own cell is empty.
    let p = Vector2::new(0.013, 0.052);
    let key = CellKey::of(p, 1.0 / cell).unwrap();
    assert!(d.get(key).is_none());
    assert!(
        nearest_in_rings(&d, p, key, 1).is_none(),
        "ring 1 holds nothing"
    );
    let g = nearest_in_rings(&d, p, key, 2).expect("found in ring 2");
    // The nearest mean among ring 2: the wall cell under the point.
    assert_eq!(
        CellKey::of(g.mean, 1.0 / cell),
        Some(CellKey { ix: 0, iy: 0 })
    );
    let on = MatchOptions {
        search_radius: 3,
        ..MatchOptions::default()
    };
    let off = MatchOptions {
        neighbor_search: false,
        ..on
    };
    let pts = [[p.x, p.y]];
    assert_eq!(
        grid.score_terms(&pts, Pose2::identity(), &on)
            .unwrap()
            .matched,
        1
    );
    assert_eq!(
        grid.score_terms(&pts, Pose2::identity(), &off)
            .unwrap()
            .matched,
        0
    );
}

/// `(M, m, S)` of a naive per-cell sum.
type Sums = (u64, Vector2<f64>, Matrix2<f64>);

#[test]
fn pyramid_levels_equal_sums_recomputed_from_scratch_after_inserts_and_removals() {
    let cell = 0.02;
    let mut grid = NdtGrid::with_levels(cell, 6).unwrap();
    let walls = common::room();
    let mut rng = StdRng::seed_from_u64(3);
    let mut world: Vec<[f64; 2]> = Vec::new();
    for i in 0..60 {
        let pose = Pose2::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-3.0..3.0),
        );
        let pts = common::urg_scan(&walls, pose, 0.01, i);
        grid.insert(&pts, pose).unwrap();
        world.extend(pts.iter().map(|p| {
            let w = pose.transform(Vector2::new(p[0], p[1]));
            [w.x, w.y]
        }));
    }
    // Remove every third fine cell, and the points in them from the naive sums.
    let fine: Vec<CellKey> = grid.level(0).unwrap().cells().keys().collect();
    let gone: std::collections::HashSet<CellKey> = fine.iter().copied().step_by(3).collect();
    let gone_list: Vec<CellKey> = gone.iter().copied().collect();
    assert_eq!(grid.remove_cells(&gone_list), gone.len());
    world.retain(|w| {
        let k = CellKey::of(Vector2::new(w[0], w[1]), 1.0 / cell).unwrap();
        !gone.contains(&k)
    });
    for l in 0..6 {
        let size = cell * f64::from(1u32 << l);
        let mut naive: std::collections::HashMap<(i64, i64), Sums> = Default::default();
        for w in &world {
            let k = ((w[0] / size).floor() as i64, (w[1] / size).floor() as i64);
            let e = naive
                .entry(k)
                .or_insert((0, Vector2::zeros(), Matrix2::zeros()));
            let v = Vector2::new(w[0], w[1]);
            e.0 += 1;
            e.1 += v;
            e.2 += v * v.transpose();
        }
        let level = grid.level(l).unwrap();
        assert_eq!(level.cells().len(), naive.len(), "level {l}");
        for (key, s) in level.cells().iter() {
            let (n, m, sxx) = naive[&(i64::from(key.ix), i64::from(key.iy))];
            let abs = s.shifted(-key.center(size));
            assert_eq!(abs.count, n);
            assert!((abs.sum - m).norm() < 1e-9 * n as f64);
            assert!((abs.scatter - sxx).norm() < 1e-8 * n as f64);
        }
    }
}

fn corridor() -> Vec<common::Segment> {
    vec![([-30.0, -1.0], [30.0, -1.0]), ([-30.0, 1.0], [30.0, 1.0])]
}

#[test]
fn corridor_is_degenerate_along_the_corridor_and_a_room_is_not() {
    for (name, walls, expect) in [
        ("corridor", corridor(), true),
        ("room", common::room(), false),
    ] {
        let mut grid = NdtGrid::new(0.02).unwrap();
        let a = Pose2::new(0.0, 0.1, 0.05);
        grid.insert(&common::urg_scan(&walls, a, 0.005, 1), a)
            .unwrap();
        let b = Pose2::new(0.3, 0.05, 0.1);
        let res = grid
            .match_scan(
                &common::urg_scan(&walls, b, 0.005, 2),
                Pose2::new(0.31, 0.06, 0.11),
                &MatchOptions {
                    levels: Some(4),
                    pair_neighbors: true,
                    ..MatchOptions::default()
                },
            )
            .unwrap();
        assert_eq!(
            !res.unconstrained.is_empty(),
            expect,
            "{name}: {:?}",
            res.unconstrained
        );
        if expect {
            assert_eq!(res.unconstrained.len(), 1, "{name}");
            let d = res.unconstrained[0];
            assert!(d[0].abs() > 0.95, "{name}: free direction {d:?} is along x");
            // The constrained directions are still recovered.
            assert!((res.pose.y - b.y).abs() < 0.005 && (res.pose.theta - b.theta).abs() < 0.005);
        }
    }
}
