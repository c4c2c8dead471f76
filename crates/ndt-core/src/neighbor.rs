//! §IV-A(1) neighbour search: a point whose own cell has no distribution is
//! paired with a nearby cell's, found ring by ring (Elias method).

use std::borrow::Borrow;

use nalgebra::Vector2;

use crate::cell::Gaussian;
use crate::distributions::{DistLookup, Distributions};
use crate::key::CellKey;

/// Pairing rule: search the square rings at Chebyshev distance 1, 2, …,
/// `radius` (in cells) around the point's own cell; in the first ring that
/// holds any distribution, take the one whose mean is nearest to the point
/// (Euclidean). `None` when no ring up to `radius` holds one.
pub fn nearest_in_rings(
    dists: &Distributions,
    point: Vector2<f64>,
    key: CellKey,
    radius: u32,
) -> Option<Gaussian> {
    nearest_in_rings_with(&mut dists.cursor(), point, key, radius)
}

/// [`nearest_in_rings`] through a cursor (the matcher's hot path: the rings
/// mostly lie in the tile of the point's own cell).
#[inline]
pub fn nearest_in_rings_with<L: DistLookup>(
    cursor: &mut L,
    point: Vector2<f64>,
    key: CellKey,
    radius: u32,
) -> Option<L::Dist> {
    nearest_in_rings_counted(cursor, point, key, radius).0
}

/// [`nearest_in_rings_with`], with the number of distributions in the ring
/// the result was taken from (0 when none was found). With at most one the
/// result does not depend on where in cell `key` the point is: a caller may
/// keep it for any point of that cell ([`crate::pairs`]).
#[inline]
pub fn nearest_in_rings_counted<L: DistLookup>(
    cursor: &mut L,
    point: Vector2<f64>,
    key: CellKey,
    radius: u32,
) -> (Option<L::Dist>, usize) {
    let radius = i32::try_from(radius).unwrap_or(i32::MAX);
    if radius >= 1 {
        // Ring 1: the 8 cells read at once, in the order of the loops below.
        let mut ring = Nearest::new(point);
        cursor.for_ring1(key, |g| ring.offer(g));
        if let Some((_, g)) = ring.best {
            return (Some(g), ring.found);
        }
    }
    for r in 2..=radius {
        let mut ring = Nearest::new(point);
        let mut consider = |dx: i32, dy: i32| {
            if let Some(g) = cursor.get(key.offset(dx, dy)) {
                ring.offer(g);
            }
        };
        for dx in -r..=r {
            consider(dx, -r);
            consider(dx, r);
        }
        for dy in (-r + 1)..r {
            consider(-r, dy);
            consider(r, dy);
        }
        if let Some((_, g)) = ring.best {
            return (Some(g), ring.found);
        }
    }
    (None, 0)
}

/// The distribution whose mean is nearest to a point among those offered
/// (the first of equally near ones), and how many were offered.
struct Nearest<D> {
    point: Vector2<f64>,
    best: Option<(f64, D)>,
    found: usize,
}

impl<D: Borrow<Gaussian> + Copy> Nearest<D> {
    #[inline(always)]
    fn new(point: Vector2<f64>) -> Self {
        Self {
            point,
            best: None,
            found: 0,
        }
    }

    #[inline(always)]
    fn offer(&mut self, g: D) {
        self.found += 1;
        let d2 = (g.borrow().mean - self.point).norm_squared();
        if self.best.is_none_or(|(b, _)| d2 < b) {
            self.best = Some((d2, g));
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::distributions::{CursorVisitor, DistOptions};
    use crate::grid::NdtGrid;
    use crate::se2::Pose2;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// `k = 10` and a 5 mm σ floor; cells finer than `shape_cell` \[m\]
    /// take their ancestor's covariance (0: each keeps its own).
    fn options(shape_cell: f64, fuse_minority: bool) -> DistOptions {
        DistOptions {
            expansion: 10.0,
            fuse_minority,
            sigma_floor: 0.005,
            shape_cell,
        }
    }

    /// The search through a store's own reader (its ring read at once).
    struct Search {
        point: Vector2<f64>,
        key: CellKey,
        radius: u32,
    }

    impl CursorVisitor for Search {
        type Out = (Option<Gaussian>, usize);
        fn visit<L: DistLookup>(self, mut cursor: L) -> Self::Out {
            let (g, n) = nearest_in_rings_counted(&mut cursor, self.point, self.key, self.radius);
            (g.map(|g| *g.borrow()), n)
        }
    }

    /// The rule of [`nearest_in_rings`] spelled out cell by cell: rings
    /// outwards, in each the cells bottom and top row by column, then the
    /// side columns by row; the first strictly nearest mean wins.
    fn reference(
        dists: &Distributions,
        point: Vector2<f64>,
        key: CellKey,
        radius: i32,
    ) -> (Option<Gaussian>, usize) {
        let mut cursor = dists.cursor();
        for r in 1..=radius {
            let mut cells = Vec::new();
            for dx in -r..=r {
                cells.extend([(dx, -r), (dx, r)]);
            }
            for dy in (-r + 1)..r {
                cells.extend([(-r, dy), (r, dy)]);
            }
            let found: Vec<Gaussian> = cells
                .iter()
                .filter_map(|&(dx, dy)| cursor.get(key.offset(dx, dy)))
                .collect();
            let mut best: Option<(f64, Gaussian)> = None;
            for g in &found {
                let d2 = (g.mean - point).norm_squared();
                if best.is_none_or(|(b, _)| d2 < b) {
                    best = Some((d2, *g));
                }
            }
            if let Some((_, g)) = best {
                return (Some(g), found.len());
            }
        }
        (None, 0)
    }

    /// On a map of scattered clusters (cells inside tiles, on their borders
    /// and where no tile is), both kinds of store give the reference's
    /// distribution and count for every point, on the fine level and a
    /// coarser one, with radii 1 to 3.
    #[test]
    fn ring_search_is_the_rule_on_both_stores() {
        let mut rng = StdRng::seed_from_u64(11);
        let mut grid = NdtGrid::new(0.02).unwrap();
        let mut points: Vec<[f64; 2]> = Vec::new();
        for _ in 0..60 {
            let c = [rng.random_range(-0.6..0.6), rng.random_range(-0.6..0.6)];
            let n = rng.random_range(1..9);
            points.extend((0..n).map(|_| {
                [
                    c[0] + rng.random_range(-0.015..0.015),
                    c[1] + rng.random_range(-0.015..0.015),
                ]
            }));
        }
        grid.insert(&points, Pose2::identity()).unwrap();
        let probes: Vec<Vector2<f64>> = (0..3000)
            .map(|_| Vector2::new(rng.random_range(-0.7..0.7), rng.random_range(-0.7..0.7)))
            .collect();
        let mut searched = 0;
        for shape_cell in [0.0, 0.32] {
            let options = options(shape_cell, true);
            for level in [0, 2] {
                let dists = grid.distributions(level, options).unwrap();
                let inv = 1.0 / (0.02 * f64::from(1u32 << level));
                for &p in &probes {
                    let key = CellKey::of(p, inv).unwrap();
                    if dists.cursor().get(key).is_some() {
                        continue;
                    }
                    for radius in 1..=3 {
                        let got = dists.visit(Search {
                            point: p,
                            key,
                            radius,
                        });
                        let want = reference(&dists, p, key, radius as i32);
                        assert_eq!(got, want, "{p:?} level {level} radius {radius}");
                        searched += usize::from(got.1 > 1);
                    }
                }
            }
        }
        assert!(searched > 1000, "{searched}");
    }

    /// Exact ties (means and distances exact in binary): the 8 cells around
    /// an empty one hold 3 points each at their centres; from the empty
    /// cell's centre the 4 edge neighbours are equally near, and the first
    /// of them in the rule's order, the one below, is taken.
    #[test]
    fn ties_go_to_the_first_cell_in_ring_order() {
        let mut grid = NdtGrid::new(0.25).unwrap();
        let mut points = Vec::new();
        for (dx, dy) in crate::table::RING1 {
            let p = [0.625 + 0.25 * f64::from(dx), 0.625 + 0.25 * f64::from(dy)];
            points.extend([p, p, p]);
        }
        grid.insert(&points, Pose2::identity()).unwrap();
        let centre = Vector2::new(0.625, 0.625);
        let key = CellKey { ix: 2, iy: 2 };
        for shape_cell in [0.0, 1.0] {
            let dists = grid.distributions(0, options(shape_cell, false)).unwrap();
            let (got, n) = dists.visit(Search {
                point: centre,
                key,
                radius: 1,
            });
            assert_eq!(n, 8);
            assert_eq!(got.unwrap().mean, Vector2::new(0.625, 0.375));
            assert_eq!((got, n), reference(&dists, centre, key, 1));
        }
    }
}
