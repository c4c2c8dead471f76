//! `NdtGrid::occupancy_probe` never hides an occupied cell and does rule out
//! empty space, after inserts and removals.

use ndt_core::{CellKey, NdtGrid, Pose2};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

#[test]
fn the_probe_admits_every_occupied_cell_and_rules_out_empty_blocks() {
    let mut rng = StdRng::seed_from_u64(5);
    let mut grid = NdtGrid::new(0.02).unwrap();
    let pts: Vec<[f64; 2]> = (0..400)
        .map(|_| [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)])
        .collect();
    grid.insert(&pts, Pose2::identity()).unwrap();
    let mut keys: Vec<CellKey> = grid.keys().collect();
    keys.sort_unstable();
    grid.remove_cells(&keys[..keys.len() / 3]);
    let mut probe = grid.occupancy_probe();
    let (mut ruled_out, mut empty) = (0, 0);
    for ix in -120..120 {
        for iy in -120..120 {
            let key = CellKey { ix, iy };
            let may = probe.may_hold(key);
            if grid.stats(key).is_some() {
                assert!(may, "{key:?} is occupied");
            } else {
                empty += 1;
                ruled_out += usize::from(!may);
            }
        }
    }
    // Blocks (16 × 16 cells) beyond the ±1 m square are empty.
    assert!(
        ruled_out * 3 > empty,
        "{ruled_out} of {empty} empty cells ruled out"
    );
    // A one-level grid has no coarser level to ask: it admits everything.
    let single = NdtGrid::with_levels(0.02, 1).unwrap();
    assert!(single.occupancy_probe().may_hold(CellKey { ix: 5, iy: 5 }));
}
