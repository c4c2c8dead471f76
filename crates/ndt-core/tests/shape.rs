//! Fine cells take the covariance of their pyramid ancestor (`shape_cell`,
//! see `ndt_core::shape`): the constructed case, and incremental updates equal
//! a fresh build.

mod common;

use nalgebra::Vector2;
use ndt_core::cell::{symmetric_eigen2, CellStats};
use ndt_core::distributions::{DistOptions, Distributions};
use ndt_core::pyramid::Level;
use ndt_core::shape::Shape;
use ndt_core::{CellKey, MatchOptions, NdtGrid, Pose2};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

#[test]
fn a_one_point_cell_on_a_wall_takes_the_walls_orientation_and_keeps_its_mean() {
    let cell = 0.02;
    let mut grid = NdtGrid::with_levels(cell, 5).unwrap();
    // A wall along a 20° line through the 32 cm cell (0, 0) (level 4), one
    // point every 3 cm: most 2 cm cells hold one point.
    let (s, c) = 20f64.to_radians().sin_cos();
    let wall: Vec<[f64; 2]> = (0..10)
        .map(|i| {
            let t = 0.01 + 0.03 * f64::from(i);
            [t * c, 0.1 + t * s]
        })
        .collect();
    grid.insert(&wall, Pose2::identity()).unwrap();
    let fine = grid.level(0).unwrap();
    let region = grid.level(4).unwrap();
    let options = |shape_cell| DistOptions {
        expansion: 10.0,
        fuse_minority: true,
        sigma_floor: 0.01,
        shape_cell,
    };
    let plain = Distributions::build(fine.cells(), cell, 0, options(0.0), None);
    let levels: Vec<Level> = (0..=4).map(|l| grid.level(l).unwrap().clone()).collect();
    let shape = Shape::new(&levels).unwrap();
    assert_eq!(shape.depth(), 4);
    assert_eq!(shape.cells().len(), region.cells().len());
    let shaped = Distributions::build(fine.cells(), cell, 0, options(0.32), Some(shape));
    let key = CellKey::of(Vector2::new(wall[3][0], wall[3][1]), 1.0 / cell).unwrap();
    assert_eq!(fine.cells().get(key).map(|s| s.count), Some(1));
    assert!(
        plain.get(key).is_none(),
        "one point and no neighbours: none"
    );
    let g = shaped.get(key).expect("shaped distribution");
    // Its own point is its mean.
    assert!((g.mean - Vector2::new(wall[3][0], wall[3][1])).norm() < 1e-12);
    // The long axis along the wall, the normal across it.
    let (l1, l2, v) = symmetric_eigen2(&g.covariance());
    let angle = v.y.atan2(v.x).to_degrees().rem_euclid(180.0);
    assert!((angle - 20.0).abs() < 1e-6, "{angle}");
    assert!((g.normal.dot(&Vector2::new(c, s))).abs() < 1e-9);
    // The wall's spread (≈ 0.27 m / √12 along it), expanded by k = 10; across
    // it the σ floor, expanded.
    let mut along = CellStats::default();
    for p in &wall {
        along.add_point(Vector2::new(p[0], p[1]));
    }
    let (_, cov) = along.mean_and_covariance().unwrap();
    let (w1, _, _) = symmetric_eigen2(&cov);
    assert!((l1 / (10.0 * w1) - 1.0).abs() < 1e-9, "{l1} {w1}");
    assert!((l2 / (10.0 * 0.01f64.powi(2)) - 1.0).abs() < 1e-9, "{l2}");
}

#[test]
fn shaped_distributions_stay_equal_to_a_fresh_build_under_inserts_and_removals() {
    let walls = common::room();
    let options = MatchOptions::default();
    assert!(options.shape_cell > 0.0);
    let mut grid = NdtGrid::new(0.02).unwrap();
    let probe = common::urg_scan(&walls, Pose2::new(0.1, 0.05, 0.3), 0.005, 7);
    let at = Pose2::new(0.103, 0.048, 0.302);
    for (i, p) in [(0.0, 0.0, 0.0), (0.4, 0.1, 0.5), (-0.3, 0.2, -0.4)]
        .iter()
        .enumerate()
    {
        let pose = Pose2::new(p.0, p.1, p.2);
        // Prepare the distributions, then change the map under them.
        let _ = grid.score_terms(&probe, at, &options).unwrap();
        let _ = grid.match_scan(&probe, at, &options).unwrap();
        grid.insert(&common::urg_scan(&walls, pose, 0.005, i as u64), pose)
            .unwrap();
        let fresh = NdtGrid::from_cell_states(0.02, &grid.cell_states()).unwrap();
        assert_eq!(
            grid.score_terms(&probe, at, &options).unwrap(),
            fresh.score_terms(&probe, at, &options).unwrap()
        );
        assert_eq!(
            grid.match_scan(&probe, at, &options).unwrap(),
            fresh.match_scan(&probe, at, &options).unwrap()
        );
    }
    let half: Vec<CellKey> = grid.keys().step_by(3).collect();
    grid.remove_cells(&half);
    let fresh = NdtGrid::from_cell_states(0.02, &grid.cell_states()).unwrap();
    assert_eq!(
        grid.match_scan(&probe, at, &options).unwrap(),
        fresh.match_scan(&probe, at, &options).unwrap()
    );
}

/// `Shape::descendants` finds exactly the occupied fine cells under the given
/// ancestors (against a filter over every fine cell), each once, after inserts
/// and removals.
#[test]
fn descendants_are_the_occupied_cells_under_the_ancestors() {
    let mut grid = NdtGrid::new(0.02).unwrap();
    let mut rng = StdRng::seed_from_u64(9);
    let mut next = move || rng.random_range(-0.5f64..0.5);
    for i in 0..6 {
        let pts: Vec<[f64; 2]> = (0..300).map(|_| [4.0 * next(), 4.0 * next()]).collect();
        grid.insert(&pts, Pose2::new(0.3 * f64::from(i), 0.0, 0.1))
            .unwrap();
    }
    let mut keys: Vec<CellKey> = grid.keys().collect();
    keys.sort_unstable();
    grid.remove_cells(&keys[..keys.len() / 4]);
    for depth in 1..=4usize {
        let levels: Vec<Level> = (0..=depth)
            .map(|l| grid.level(l).unwrap().clone())
            .collect();
        let shape = Shape::new(&levels).unwrap();
        // Every other ancestor of the shape level, plus one with no cell.
        let mut ancestors: rustc_hash::FxHashSet<CellKey> =
            shape.cells().keys().step_by(2).collect();
        ancestors.insert(CellKey {
            ix: 10_000,
            iy: 10_000,
        });
        let found = shape.descendants(&ancestors);
        for (a, k, stats) in &found {
            assert_eq!(ndt_core::pyramid::coarse_key(*k, depth), *a);
            assert_eq!(grid.stats(*k), Some(*stats));
        }
        let mut got: Vec<CellKey> = found.iter().map(|f| f.1).collect();
        let n = got.len();
        got.sort_unstable();
        got.dedup();
        assert_eq!(got.len(), n, "a cell listed twice");
        let mut want: Vec<CellKey> = grid
            .keys()
            .filter(|k| ancestors.contains(&ndt_core::pyramid::coarse_key(*k, depth)))
            .collect();
        want.sort_unstable();
        assert!(!want.is_empty());
        assert_eq!(got, want, "depth {depth}");
    }
}
