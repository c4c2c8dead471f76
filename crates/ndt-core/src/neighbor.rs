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
    for r in 1..=radius {
        let mut best: Option<(f64, L::Dist)> = None;
        let mut found = 0;
        let mut consider = |dx: i32, dy: i32| {
            if let Some(g) = cursor.get(key.offset(dx, dy)) {
                found += 1;
                let d2 = (g.borrow().mean - point).norm_squared();
                if best.is_none_or(|(b, _)| d2 < b) {
                    best = Some((d2, g));
                }
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
        if let Some((_, g)) = best {
            return (Some(g), found);
        }
    }
    (None, 0)
}
