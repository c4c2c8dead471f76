//! Helpers shared by the crate's unit tests.

use nalgebra::{Matrix3, Vector3};
use rand::rngs::StdRng;
use rand::Rng;

/// A symmetric 3 × 3 matrix with `eigenvalues` along random orthogonal
/// directions (exactly symmetric, like the accumulated Hessians).
pub(crate) fn random_symmetric(rng: &mut StdRng, eigenvalues: [f64; 3]) -> Matrix3<f64> {
    let q = nalgebra::Rotation3::from_euler_angles(
        rng.random_range(-3.0..3.0),
        rng.random_range(-1.5..1.5),
        rng.random_range(-3.0..3.0),
    );
    let m =
        q.matrix() * Matrix3::from_diagonal(&Vector3::from(eigenvalues)) * q.matrix().transpose();
    (m + m.transpose()) * 0.5
}

/// The distribution options the grids' tests prepare and compare: shaped
/// fine levels (the match's default) and every level on its own (the
/// odometry loop's).
pub(crate) const GRID_OPTIONS: [crate::distributions::DistOptions; 2] = [
    crate::distributions::DistOptions {
        expansion: 10.0,
        fuse_minority: true,
        sigma_floor: 0.02,
        shape_cell: 0.32,
    },
    crate::distributions::DistOptions {
        expansion: 30.0,
        fuse_minority: true,
        sigma_floor: 0.01,
        shape_cell: 0.0,
    },
];

/// Every level's sums and the distributions of every [`GRID_OPTIONS`] of
/// `a` and `b` are equal, bit for bit (the distributions are built where
/// not yet prepared).
#[allow(clippy::unwrap_used)]
pub(crate) fn assert_same_grids(a: &crate::NdtGrid, b: &crate::NdtGrid) {
    for l in 0..a.levels() {
        let cells = |g: &crate::NdtGrid| {
            let mut v: Vec<_> = g
                .level(l)
                .unwrap()
                .cells()
                .iter()
                .map(|(k, c)| (k, *c))
                .collect();
            v.sort_unstable_by_key(|(k, _)| *k);
            v
        };
        let (ca, cb) = (cells(a), cells(b));
        assert_eq!(ca, cb, "level {l}");
        for options in GRID_OPTIONS {
            let (da, db) = (
                a.distributions(l, options).unwrap(),
                b.distributions(l, options).unwrap(),
            );
            assert_eq!(da.len(), db.len(), "level {l}");
            for (k, _) in &ca {
                assert_eq!(da.get(*k), db.get(*k), "level {l} cell {k:?}");
            }
        }
    }
}

/// A room's walls (4 × 3 m, a box inside) seen from `pose`: scan-frame
/// points, about a third of them drawn by `rng`.
pub(crate) fn room_scan(pose: crate::Pose2, rng: &mut StdRng) -> Vec<[f64; 2]> {
    let mut world = Vec::new();
    for i in 0..400 {
        let t = f64::from(i) / 400.0;
        world.push([-2.0 + 4.0 * t, -1.5]);
        world.push([-2.0 + 4.0 * t, 1.5]);
        world.push([-2.0, -1.5 + 3.0 * t]);
        world.push([2.0, -1.5 + 3.0 * t]);
        world.push([0.5 + 0.3 * t, 0.2]);
    }
    let to_scan = pose.inverse();
    world
        .iter()
        .filter(|_| rng.random_range(0.0..1.0) < 0.35)
        .map(|p| {
            let q = to_scan.transform(nalgebra::Vector2::new(p[0], p[1]));
            [q.x, q.y]
        })
        .collect()
}

/// A 2 cm grid of 6 [`room_scan`]s along a short path.
#[allow(clippy::unwrap_used)]
pub(crate) fn room_map(rng: &mut StdRng) -> crate::NdtGrid {
    let mut grid = crate::NdtGrid::new(0.02).unwrap();
    for k in 0..6 {
        let at = crate::Pose2::new(
            0.1 * f64::from(k),
            -0.05 * f64::from(k),
            0.02 * f64::from(k),
        );
        grid.insert(&room_scan(at, rng), at).unwrap();
    }
    grid
}
