//! `NdtGrid::occupancy_probe` never hides an occupied cell and does rule out
//! empty space, on its blocks and on its smaller blocks, after inserts and
//! removals.

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
    assert_eq!((probe.block_bits(), probe.inner_bits()), (Some(4), Some(2)));
    let (mut ruled_out, mut ruled_out_inner, mut empty) = (0, 0, 0);
    for ix in -120..120 {
        for iy in -120..120 {
            let key = CellKey { ix, iy };
            let (may, may_inner) = (probe.may_hold(key), probe.may_hold_inner(key));
            if grid.stats(key).is_some() {
                assert!(may && may_inner, "{key:?} is occupied");
            } else {
                empty += 1;
                ruled_out += usize::from(!may);
                ruled_out_inner += usize::from(!may_inner);
            }
        }
    }
    // Blocks (16 × 16 cells) beyond the ±1 m square are empty, and inside
    // it most of the smaller blocks (4 × 4) of a sparse scatter are too.
    assert!(
        ruled_out * 3 > empty,
        "{ruled_out} of {empty} empty cells ruled out"
    );
    assert!(
        ruled_out_inner > ruled_out + (empty - ruled_out) / 2,
        "{ruled_out_inner} of {empty} empty cells ruled out by the smaller blocks"
    );
    // The probe reads the occupancy, not the pyramid: a one-level grid
    // rules out empty blocks as well, with the same block sizes.
    let mut single = NdtGrid::with_levels(0.02, 1).unwrap();
    single.insert(&pts, Pose2::identity()).unwrap();
    single.remove_cells(&keys[..keys.len() / 3]);
    let mut one = single.occupancy_probe();
    let mut six = grid.occupancy_probe();
    assert_eq!((one.block_bits(), one.inner_bits()), (Some(4), Some(2)));
    for ix in -120..120 {
        for iy in -120..120 {
            let key = CellKey { ix, iy };
            assert_eq!(one.may_hold(key), six.may_hold(key), "{key:?}");
            assert_eq!(one.may_hold_inner(key), six.may_hold_inner(key), "{key:?}");
        }
    }
}
