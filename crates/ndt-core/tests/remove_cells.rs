//! `NdtGrid::remove_cells` keeps the prepared distributions exactly as a
//! grid built from the remaining points would have them (§IV-A(3) fusion
//! included).

mod common;

use ndt_core::{CellKey, MatchOptions, NdtGrid, Pose2};

fn key_of(p: [f64; 2], pose: Pose2, cell: f64) -> CellKey {
    let w = pose.transform(ndt_core::nalgebra::Vector2::new(p[0], p[1]));
    CellKey::of(w, 1.0 / cell).unwrap()
}

#[test]
fn removal_updates_distributions_like_a_fresh_build() {
    let cell = 0.02;
    let walls = common::room();
    let poses = [Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.3, 0.2, 1.0)];
    let scans: Vec<Vec<[f64; 2]>> = poses
        .iter()
        .enumerate()
        .map(|(i, &p)| common::urg_scan(&walls, p, 0.005, i as u64))
        .collect();
    let probe = common::urg_scan(&walls, Pose2::new(0.1, 0.05, 0.3), 0.005, 7);
    let at = Pose2::new(0.11, 0.04, 0.31);
    let fused = MatchOptions::default();
    let plain = MatchOptions {
        fuse_minority: false,
        ..MatchOptions::default()
    };

    let mut grid = NdtGrid::new(cell).unwrap();
    for (s, &p) in scans.iter().zip(&poses) {
        grid.insert(s, p).unwrap();
    }
    // Prepare both distribution sets, then remove every 7th cell plus a few
    // cells that do not exist.
    grid.score_terms(&probe, at, &fused).unwrap();
    grid.score_terms(&probe, at, &plain).unwrap();
    let cells = grid.cells();
    let mut doomed: Vec<CellKey> = cells.iter().step_by(7).map(|c| c.key).collect();
    let n_doomed = doomed.len();
    doomed.push(CellKey { ix: 99_999, iy: 5 });
    doomed.push(doomed[0]);
    assert_eq!(grid.remove_cells(&doomed), n_doomed);
    assert_eq!(grid.len(), cells.len() - n_doomed);
    assert_eq!(grid.remove_cells(&doomed), 0);

    // The same map built from the surviving points only, in the same order.
    let gone: std::collections::HashSet<CellKey> = doomed.into_iter().collect();
    let mut fresh = NdtGrid::new(cell).unwrap();
    for (s, &p) in scans.iter().zip(&poses) {
        let kept: Vec<[f64; 2]> = s
            .iter()
            .copied()
            .filter(|&q| !gone.contains(&key_of(q, p, cell)))
            .collect();
        fresh.insert(&kept, p).unwrap();
    }
    assert_eq!(fresh.cells(), grid.cells());
    for options in [fused, plain] {
        let a = grid.score_terms(&probe, at, &options).unwrap();
        let b = fresh.score_terms(&probe, at, &options).unwrap();
        assert_eq!(a.matched, b.matched);
        assert!(
            (a.score - b.score).abs() < 1e-9,
            "{} vs {}",
            a.score,
            b.score
        );
        assert!((a.gradient - b.gradient).norm() < 1e-6);
        assert!((a.hessian - b.hessian).norm() < 1e-4 * (1.0 + b.hessian.norm()));
    }
}

/// The grid's occupancy mask (what the §V walks ask first) holds exactly the
/// cells with sums, through inserts, removals and a rebuild from the states.
#[test]
fn occupancy_mask_follows_inserts_removals_and_rebuilds() {
    let cell = 0.02;
    let walls = common::room();
    let mut grid = NdtGrid::new(cell).unwrap();
    let check = |grid: &NdtGrid| {
        let bounds = grid.key_bounds().unwrap();
        let mut occupancy = grid.occupancy();
        let mut held = 0;
        for iy in bounds.min.iy - 3..=bounds.max.iy + 3 {
            for ix in bounds.min.ix - 3..=bounds.max.ix + 3 {
                let key = CellKey { ix, iy };
                assert_eq!(
                    occupancy.contains(key),
                    grid.stats(key).is_some(),
                    "{key:?}"
                );
                held += usize::from(occupancy.contains(key));
            }
        }
        assert_eq!(held, grid.len());
    };
    for i in 0..4u32 {
        let pose = Pose2::new(0.2 * f64::from(i), -0.1 * f64::from(i), 0.4 * f64::from(i));
        grid.insert(&common::urg_scan(&walls, pose, 0.005, u64::from(i)), pose)
            .unwrap();
        check(&grid);
        let doomed: Vec<CellKey> = grid.keys().step_by(5).collect();
        assert_eq!(grid.remove_cells(&doomed), doomed.len());
        check(&grid);
    }
    let rebuilt = NdtGrid::from_cell_states(cell, &grid.cell_states()).unwrap();
    check(&rebuilt);
}
