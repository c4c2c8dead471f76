//! Cell statistics (eq. 6) against a naive per-cell computation.

use std::collections::BTreeMap;

use ndt_core::{NdtGrid, Pose2};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

type Naive = BTreeMap<(i64, i64), (u64, [f64; 2], [f64; 4])>;

fn naive(points: &[[f64; 2]], cell: f64) -> Naive {
    let mut out: Naive = BTreeMap::new();
    for p in points {
        let k = ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
        let e = out.entry(k).or_insert((0, [0.0; 2], [0.0; 4]));
        e.0 += 1;
        e.1[0] += p[0];
        e.1[1] += p[1];
        e.2[0] += p[0] * p[0];
        e.2[1] += p[0] * p[1];
        e.2[2] += p[1] * p[0];
        e.2[3] += p[1] * p[1];
    }
    out
}

fn check(cell: f64, centre: [f64; 2], spread: f64, seed: u64) {
    let mut rng = StdRng::seed_from_u64(seed);
    let points: Vec<[f64; 2]> = (0..3000)
        .map(|_| {
            [
                centre[0] + rng.random_range(-spread..spread),
                centre[1] + rng.random_range(-spread..spread),
            ]
        })
        .collect();
    let mut grid = NdtGrid::new(cell).unwrap();
    // Insert in three batches at the identity pose.
    for chunk in points.chunks(1000) {
        grid.insert(chunk, Pose2::identity()).unwrap();
    }
    let expected = naive(&points, cell);
    let got = grid.cells();
    assert_eq!(got.len(), expected.len());
    assert_eq!(grid.len(), expected.len());
    for (rec, ((kx, ky), (n, m, s))) in got.iter().zip(expected.iter()) {
        assert_eq!((i64::from(rec.key.ix), i64::from(rec.key.iy)), (*kx, *ky));
        assert_eq!(rec.count, *n);
        let scale = 1.0 + centre[0].abs().max(centre[1].abs());
        for (i, mi) in m.iter().enumerate() {
            assert!((rec.sum[i] - mi).abs() <= 1e-9 * scale * *n as f64);
        }
        for (i, v) in s.iter().enumerate() {
            let g = rec.scatter[(i / 2, i % 2)];
            assert!(
                (g - v).abs() <= 1e-9 * scale * scale * *n as f64,
                "S[{i}] {g} vs {v}"
            );
        }
    }
}

#[test]
fn sums_match_naive_computation_for_several_cell_sizes() {
    for (i, cell) in [0.02, 0.05, 0.2, 1.0].iter().enumerate() {
        check(*cell, [0.0, 0.0], 1.0, i as u64);
    }
}

#[test]
fn negative_and_far_coordinates_use_floor_division() {
    check(0.02, [-3.7, -12.1], 0.3, 7);
    check(0.02, [-600.0, 450.0], 0.3, 8);
    let mut grid = NdtGrid::new(0.1).unwrap();
    grid.insert(&[[-0.05, -0.0001], [0.05, 0.0]], Pose2::identity())
        .unwrap();
    let keys: Vec<(i32, i32)> = grid.cells().iter().map(|c| (c.key.ix, c.key.iy)).collect();
    assert_eq!(keys, vec![(-1, -1), (0, 0)]);
}

#[test]
fn insert_at_a_pose_equals_inserting_transformed_points() {
    let pose = Pose2::new(1.3, -0.7, 0.9);
    let pts = [[0.3, 0.1], [1.2, -0.4], [0.31, 0.11], [2.0, 2.0]];
    let mut a = NdtGrid::new(0.05).unwrap();
    a.insert(&pts, pose).unwrap();
    let world: Vec<[f64; 2]> = pts
        .iter()
        .map(|p| {
            let w = pose.transform(nalgebra::Vector2::new(p[0], p[1]));
            [w.x, w.y]
        })
        .collect();
    let mut b = NdtGrid::new(0.05).unwrap();
    b.insert(&world, Pose2::identity()).unwrap();
    assert_eq!(a.cells(), b.cells());
}

#[test]
fn failed_insert_leaves_the_grid_unchanged() {
    let mut grid = NdtGrid::new(0.02).unwrap();
    grid.insert(&[[1.0, 1.0]], Pose2::identity()).unwrap();
    let before = grid.cells();
    assert!(grid
        .insert(&[[0.5, 0.5], [f64::NAN, 0.0]], Pose2::identity())
        .is_err());
    assert!(grid
        .insert(&[[0.5, 0.5], [1e12, 0.0]], Pose2::identity())
        .is_err());
    assert!(grid
        .insert(&[[0.5, 0.5]], Pose2::new(0.0, f64::INFINITY, 0.0))
        .is_err());
    assert_eq!(grid.cells(), before);
}

#[test]
fn overflow_error_names_the_point() {
    let mut grid = NdtGrid::new(0.02).unwrap();
    let err = grid
        .insert(&[[0.0, 0.0], [3e7, 1.0]], Pose2::identity())
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "points: point 1 at (3e7, 1) m is outside the grid's range of ±21474836.48 m \
         (cell index would overflow)"
    );
}

#[test]
fn invalid_cell_size_is_rejected() {
    for bad in [0.0, -0.1, f64::NAN, f64::INFINITY, 1e-8, 0.000_999] {
        let msg = NdtGrid::new(bad).unwrap_err().to_string();
        assert!(
            msg.starts_with("cell_size: expected a finite cell size >= 0.001 m, got"),
            "{msg}"
        );
    }
    assert!(NdtGrid::new(0.001).is_ok());
}
