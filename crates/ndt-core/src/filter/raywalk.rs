//! The cells along a beam: the grid traversal of Amanatides & Woo (1987),
//! shared by §V step b-2 (cells short of a new hit) and step d (the radial
//! walk from the sensor to the hit).

use nalgebra::Vector2;

use crate::key::{CellKey, KeyBounds};

/// Visits, in order from `from` to `to` (map frame \[m\]), every cell of size
/// `cell_size` \[m\] that the segment crosses, calling `visit(key, t_in, t_out)`
/// with the distances \[m\] from `from` at which the segment enters and leaves
/// the cell. Stops early when `visit` returns `false`.
///
/// Nothing is visited when an end point is not finite or its cell index
/// would overflow (see [`CellKey::of`]).
pub fn walk_cells(
    from: Vector2<f64>,
    to: Vector2<f64>,
    cell_size: f64,
    visit: impl FnMut(CellKey, f64, f64) -> bool,
) {
    walk_until(from, to, cell_size, f64::INFINITY, &mut NoSkip, visit);
}

/// Square blocks of `2^bits × 2^bits` cells that a walk may cross without
/// visiting their cells (see [`walk_cells_in_skipping`]).
pub trait EmptyBlocks {
    /// log2 of the block side \[cells\]; `None`: no block is skipped.
    fn block_bits(&self) -> Option<u32>;
    /// `true` when the block of cell `key` holds no cell the visitor would
    /// act on.
    fn is_empty(&mut self, key: CellKey) -> bool;
    /// log2 of the side \[cells\] of smaller blocks, looked at inside the
    /// blocks that are not empty; `None` (the default): none.
    fn inner_bits(&self) -> Option<u32> {
        None
    }
    /// [`EmptyBlocks::is_empty`] for the smaller blocks.
    fn inner_is_empty(&mut self, _key: CellKey) -> bool {
        false
    }
    /// log2 of the side \[cells\] of the largest empty block holding
    /// `key`; `None`: no such block. By default the block of
    /// [`EmptyBlocks::block_bits`], else the smaller one of
    /// [`EmptyBlocks::inner_bits`]; a source that answers several sizes from
    /// one look-up overrides it.
    #[inline]
    fn empty_block(&mut self, key: CellKey) -> Option<u32> {
        if let Some(b) = self.block_bits().filter(|&b| b < 31) {
            if self.is_empty(key) {
                return Some(b);
            }
        }
        self.inner_bits()
            .filter(|&b| b < 31 && self.inner_is_empty(key))
    }
}

/// The blocks a grid's occupancy shows empty ([`crate::occupancy::OccupancyProbe`]).
impl EmptyBlocks for crate::occupancy::OccupancyProbe<'_> {
    fn block_bits(&self) -> Option<u32> {
        crate::occupancy::OccupancyProbe::block_bits(self)
    }
    fn is_empty(&mut self, key: CellKey) -> bool {
        !self.may_hold(key)
    }
    fn inner_bits(&self) -> Option<u32> {
        crate::occupancy::OccupancyProbe::inner_bits(self)
    }
    fn inner_is_empty(&mut self, key: CellKey) -> bool {
        !self.may_hold_inner(key)
    }
    /// Four sizes, 32 × 32 down to 4 × 4 cells, from one word
    /// ([`crate::occupancy::OccupancyProbe::empty_block`]).
    #[inline]
    fn empty_block(&mut self, key: CellKey) -> Option<u32> {
        crate::occupancy::OccupancyProbe::empty_block(self, key)
    }
}

/// Skips nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoSkip;

impl EmptyBlocks for NoSkip {
    fn block_bits(&self) -> Option<u32> {
        None
    }
    fn is_empty(&mut self, _: CellKey) -> bool {
        false
    }
}

/// [`walk_cells`] restricted to the cells of `region` (see
/// [`crate::NdtGrid::key_bounds`]) and a margin of one cell: the part of the
/// segment outside is not walked. Callers that only look for occupied cells
/// see the same cells, at a cost bounded by the map's extent instead of the
/// beam's length (a driver's 10⁶ m range would otherwise walk 5·10⁷ cells of
/// 2 cm). When the segment starts inside, the walk is [`walk_cells`]'s, cut
/// short where it leaves; a segment starting outside is walked from where it
/// enters (distances passed to `visit` are then from that point; where the
/// segment runs exactly through a cell corner, the walk from there may step
/// into the other of the two cells touching it, as a walk from any other
/// start point may). `None` (an empty grid) walks nothing.
pub fn walk_cells_in(
    from: Vector2<f64>,
    to: Vector2<f64>,
    cell_size: f64,
    region: Option<KeyBounds>,
    visit: impl FnMut(CellKey, f64, f64) -> bool,
) {
    walk_cells_in_skipping(from, to, cell_size, region, &mut NoSkip, visit);
}

/// [`walk_cells_in`] that crosses the blocks `skip` reports empty without
/// visiting their cells. For a visitor that does nothing and returns `true`
/// on those cells it is the same walk: the traversal's state after a skipped
/// block is the one the cell-by-cell walk reaches there, to the bit (both
/// take the distance of an axis's `k`-th boundary crossing as the same
/// product, `first + k · step`), so every cell outside them is visited with
/// the same distances. The walk ends in an empty block holding the end
/// point (a segment meets a square in one piece, so the rest of it lies in
/// that block). A beam through free space then costs a few operations per
/// block instead of a visit per cell (the §V walks,
/// [`crate::filter::walkmap`]); at every step the largest empty block
/// [`EmptyBlocks::empty_block`] reports is crossed, so inside a block that
/// is not empty the smaller empty ones are crossed the same way.
pub fn walk_cells_in_skipping(
    from: Vector2<f64>,
    to: Vector2<f64>,
    cell_size: f64,
    region: Option<KeyBounds>,
    skip: &mut impl EmptyBlocks,
    visit: impl FnMut(CellKey, f64, f64) -> bool,
) {
    let Some(region) = region else {
        return;
    };
    // The region with a one-cell margin, in metres.
    let lo = [
        (f64::from(region.min.ix) - 1.0) * cell_size,
        (f64::from(region.min.iy) - 1.0) * cell_size,
    ];
    let hi = [
        (f64::from(region.max.ix) + 2.0) * cell_size,
        (f64::from(region.max.iy) + 2.0) * cell_size,
    ];
    // Liang–Barsky: the parameter interval [t0, t1] of `from + t (to − from)`
    // inside the rectangle.
    let delta = to - from;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for axis in 0..2 {
        let (o, d) = (from[axis], delta[axis]);
        if d == 0.0 {
            if !(lo[axis] <= o && o <= hi[axis]) {
                return;
            }
        } else {
            let (a, b) = ((lo[axis] - o) / d, (hi[axis] - o) / d);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    // Also rejects NaN.
    if t0
        .partial_cmp(&t1)
        .is_none_or(|o| o == std::cmp::Ordering::Greater)
    {
        return;
    }
    let length = delta.norm();
    if t0 > 0.0 {
        walk_until(
            from + delta * t0,
            to,
            cell_size,
            (t1 - t0) * length,
            skip,
            visit,
        );
    } else {
        walk_until(from, to, cell_size, t1 * length, skip, visit);
    }
}

/// The distance of an axis's boundary crossing `k` (0: the first, at
/// `first`; `d` apart), as a product, not a running sum: a block is then
/// crossed in a few operations (see [`walk_until`]), and the cell-by-cell
/// walk takes exactly the same values.
#[inline(always)]
fn crossing(first: f64, d: f64, k: i64) -> f64 {
    first + k as f64 * d
}

/// Crossings [`first_not`] counts one by one before it estimates.
const COUNTED: usize = 4;

/// The first crossing `k ≥ from` of an axis ([`crossing`]; `d > 0`, or
/// `d = 0` with `first` infinite; `inv_d ≈ 1 / d`, for the estimate only;
/// `at`: crossing `from`'s distance, which the caller holds) whose distance
/// `c` is not `before(c, target)` (`target` finite), and that distance. The
/// first [`COUNTED`] are compared one by one (in a small block, or on a
/// beam close to the other axis, that is all there is, and those
/// comparisons do not wait on one another); beyond them `k` is estimated as
/// `(target − first) · inv_d` and corrected by the comparisons a count
/// would make, so it is the same `k` (the distances grow with `k`, and
/// `before` holds below some `k` and fails from there on). Crossing a block
/// of 32 cells on a slope near 1 then costs a few comparisons instead of
/// 32. Estimating from the first crossing (with a division) cost
/// criterion's `odometry_step/181_beams_2cm` 4 % (benches/SPEED_LOG.md,
/// session 25).
#[inline]
fn first_not(
    (first, d, inv_d): (f64, f64, f64),
    (from, at): (i64, f64),
    target: f64,
    before: impl Fn(f64, f64) -> bool,
) -> (i64, f64) {
    let (mut k, mut c) = (from, at);
    for _ in 0..COUNTED {
        if !before(c, target) {
            return (k, c);
        }
        k += 1;
        c = crossing(first, d, k);
    }
    let from = k;
    // `as` saturates (and takes NaN to 0): any estimate is corrected below.
    k = (((target - first) * inv_d) as i64).max(from);
    c = crossing(first, d, k);
    if before(c, target) {
        loop {
            k += 1;
            c = crossing(first, d, k);
            if !before(c, target) {
                return (k, c);
            }
        }
    }
    while k > from {
        let p = crossing(first, d, k - 1);
        if before(p, target) {
            break;
        }
        k -= 1;
        c = p;
    }
    (k, c)
}

/// [`walk_cells`], stopping before the first cell entered farther than
/// `stop` \[m\] from `from`, crossing the empty blocks of `skip` (see
/// [`walk_cells_in_skipping`]).
fn walk_until(
    from: Vector2<f64>,
    to: Vector2<f64>,
    cell_size: f64,
    stop: f64,
    skip: &mut impl EmptyBlocks,
    mut visit: impl FnMut(CellKey, f64, f64) -> bool,
) {
    let inv = 1.0 / cell_size;
    let (Some(mut key), Some(last)) = (CellKey::of(from, inv), CellKey::of(to, inv)) else {
        return;
    };
    let delta = to - from;
    let length = delta.norm();
    if length == 0.0 {
        visit(key, 0.0, 0.0);
        return;
    }
    let dir = delta / length;
    // Per axis: the step (±1), the distance to the first boundary crossing,
    // and the distance between crossings, with its reciprocal `|d| / cell`
    // for the estimates of `first_not` (0 where never crossed).
    let axis = |d: f64, origin: f64, index: i32| -> (i32, f64, f64) {
        if d > 0.0 {
            let boundary = (f64::from(index) + 1.0) * cell_size;
            (1, (boundary - origin) / d, cell_size / d)
        } else if d < 0.0 {
            let boundary = f64::from(index) * cell_size;
            (-1, (boundary - origin) / d, -cell_size / d)
        } else {
            // Never crossed: every crossing at infinity (k · 0 adds 0).
            (0, f64::INFINITY, 0.0)
        }
    };
    let (step_x, first_x, delta_x) = axis(dir.x, from.x, key.ix);
    let (step_y, first_y, delta_y) = axis(dir.y, from.y, key.iy);
    let (inv_x, inv_y) = (dir.x.abs() * inv, dir.y.abs() * inv);
    // Crossings passed per axis, and the distance of the next one.
    let (mut kx, mut ky) = (0i64, 0i64);
    let (mut next_x, mut next_y) = (first_x, first_y);
    // The exact number of cells is |Δix| + |Δiy| + 1; round-off at a corner
    // may cost one more, never more than that.
    let budget = (i64::from(last.ix) - i64::from(key.ix)).unsigned_abs()
        + (i64::from(last.iy) - i64::from(key.iy)).unsigned_abs()
        + 2;
    let mut t_in = 0.0;
    let mut walked: u64 = 0;
    while walked < budget {
        if t_in > stop {
            return;
        }
        // The largest empty block of `key`; when it holds the end point
        // too, so does it the rest of the walk (a segment meets a square in
        // one piece): nothing is left to visit.
        let empty = skip.empty_block(key).filter(|&b| b < 31);
        if let Some(b) = empty {
            if crate::pyramid::coarse_key(key, b as usize)
                == crate::pyramid::coarse_key(last, b as usize)
            {
                return;
            }
            // Cross the block as the loop below would, without visits:
            // the `n`-th crossing along an axis leaves the block, and the
            // axis whose leaving crossing comes first (x on a tie, as
            // below) is the one the walk leaves by; the other axis is
            // crossed wherever the loop would cross it before that
            // (`first_not`: where its crossings stop coming first).
            let side = 1i32 << b;
            let exits = |step: i32, index: i32| -> Option<i64> {
                let lo = (index >> b) << b;
                match step {
                    1 => Some(i64::from(lo + side - index)),
                    -1 => Some(i64::from(index - lo + 1)),
                    _ => None,
                }
            };
            let (nx, ny) = (exits(step_x, key.ix), exits(step_y, key.iy));
            let by_x = match (nx, ny) {
                (None, _) => false,
                (_, None) => true,
                (Some(nx), Some(ny)) => {
                    crossing(first_x, delta_x, kx + nx - 1)
                        <= crossing(first_y, delta_y, ky + ny - 1)
                }
            };
            let (kx0, ky0) = (kx, ky);
            if let (true, Some(nx)) = (by_x, nx) {
                kx += nx - 1;
                next_x = crossing(first_x, delta_x, kx);
                (ky, next_y) =
                    first_not((first_y, delta_y, inv_y), (ky, next_y), next_x, |c, t| {
                        c < t
                    });
            } else if let Some(ny) = ny {
                ky += ny - 1;
                next_y = crossing(first_y, delta_y, ky);
                (kx, next_x) =
                    first_not((first_x, delta_x, inv_x), (kx, next_x), next_y, |c, t| {
                        c <= t
                    });
            }
            // The exit distance of the block's last cell, then the step
            // out.
            t_in = next_x.min(next_y).min(length);
            if by_x {
                kx += 1;
                next_x = crossing(first_x, delta_x, kx);
            } else {
                ky += 1;
                next_y = crossing(first_y, delta_y, ky);
            }
            // At most a block's side of crossings per axis.
            let (sx, sy) = (kx - kx0, ky - ky0);
            key.ix += step_x * sx as i32;
            key.iy += step_y * sy as i32;
            walked += (sx + sy) as u64;
            continue;
        }
        let t_out = next_x.min(next_y).min(length);
        // Walk until the end point's own cell, even when the segment only
        // touches it (an end on a cell boundary).
        if !visit(key, t_in, t_out) || key == last {
            return;
        }
        if next_x <= next_y {
            key.ix += step_x;
            kx += 1;
            next_x = crossing(first_x, delta_x, kx);
        } else {
            key.iy += step_y;
            ky += 1;
            next_y = crossing(first_y, delta_y, ky);
        }
        t_in = t_out;
        walked += 1;
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    fn walk(from: [f64; 2], to: [f64; 2], cell: f64) -> Vec<(CellKey, f64, f64)> {
        let mut out = Vec::new();
        walk_cells(
            Vector2::new(from[0], from[1]),
            Vector2::new(to[0], to[1]),
            cell,
            |k, a, b| {
                out.push((k, a, b));
                true
            },
        );
        out
    }

    #[test]
    fn visits_exactly_the_cells_a_dense_sampling_touches() {
        let cell = 0.02;
        let cases = [
            ([0.011, 0.013], [0.91, 0.35]),
            ([-0.3, 0.25], [0.7, -0.61]),
            ([0.5, 0.5], [0.5, -0.5]),
            ([-1.234, 0.0], [1.0, 0.0001]),
            ([0.0, 0.0], [-0.37, -0.81]),
        ];
        for (a, b) in cases {
            let cells = walk(a, b, cell);
            let keys: Vec<CellKey> = cells.iter().map(|c| c.0).collect();
            // Consecutive cells are 4-neighbours and distances increase.
            for w in cells.windows(2) {
                let (k0, _, out0) = w[0];
                let (k1, in1, _) = w[1];
                assert_eq!((k0.ix - k1.ix).abs() + (k0.iy - k1.iy).abs(), 1);
                assert!((out0 - in1).abs() < 1e-12 && in1 >= w[0].1);
            }
            // Every densely sampled point lies in a visited cell.
            let (pa, pb) = (Vector2::new(a[0], a[1]), Vector2::new(b[0], b[1]));
            for i in 0..=20_000 {
                let p = pa + (pb - pa) * (f64::from(i) / 20_000.0);
                let k = CellKey::of(p, 1.0 / cell).unwrap();
                assert!(keys.contains(&k), "{k:?} missing for {a:?} -> {b:?}");
            }
            // And no cell is visited that the segment does not cross (up to
            // a corner touch): its entry/exit span is positive or it is an end.
            let total = (pb - pa).norm();
            assert!((cells.last().unwrap().2 - total).abs() < 1e-12);
            assert_eq!(keys.first(), CellKey::of(pa, 1.0 / cell).as_ref());
            assert_eq!(keys.last(), CellKey::of(pb, 1.0 / cell).as_ref());
        }
    }

    #[test]
    fn stops_when_asked_and_handles_degenerate_segments() {
        let mut n = 0;
        walk_cells(
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            0.1,
            |_, _, _| {
                n += 1;
                n < 3
            },
        );
        assert_eq!(n, 3);
        assert_eq!(walk([0.05, 0.05], [0.05, 0.05], 0.1).len(), 1);
        assert!(walk([f64::NAN, 0.0], [1.0, 0.0], 0.1).is_empty());
        // Along an axis: one cell per 0.1 m.
        assert_eq!(walk([0.05, 0.05], [0.95, 0.05], 0.1).len(), 10);
    }

    #[test]
    fn the_walk_in_a_region_sees_the_same_cells_there_and_skips_the_rest() {
        let cell = 0.02;
        let inv = 1.0 / cell;
        let region = KeyBounds::of(CellKey::of(Vector2::new(-1.0, -0.5), inv).unwrap())
            .including(CellKey::of(Vector2::new(1.0, 0.7), inv).unwrap());
        let inside = |k: &CellKey| {
            (region.min.ix..=region.max.ix).contains(&k.ix)
                && (region.min.iy..=region.max.iy).contains(&k.iy)
        };
        let cases = [
            // Inside to inside, inside to far outside, outside through, outside
            // missing it, and a 10^6 m beam.
            ([0.011, 0.013], [0.91, 0.35]),
            ([0.3, 0.2], [40.0, -17.0]),
            ([-30.0, 0.1], [30.0, 0.33]),
            ([-30.0, 5.0], [30.0, 5.0]),
            ([0.05, 0.05], [1.0e6, 3.0e5]),
        ];
        for (a, b) in cases {
            let (pa, pb) = (Vector2::new(a[0], a[1]), Vector2::new(b[0], b[1]));
            let mut all = Vec::new();
            if (pb - pa).norm() < 1e3 {
                walk_cells(pa, pb, cell, |k, _, _| {
                    all.push(k);
                    true
                });
            }
            let mut clipped = Vec::new();
            walk_cells_in(pa, pb, cell, Some(region), |k, _, _| {
                clipped.push(k);
                true
            });
            // Never more than the region's extent (plus its margin).
            let span = (region.max.ix - region.min.ix + region.max.iy - region.min.iy) as usize;
            assert!(clipped.len() <= span + 8, "{} cells", clipped.len());
            let want: Vec<CellKey> = all.into_iter().filter(|k| inside(k)).collect();
            let got: Vec<CellKey> = clipped.into_iter().filter(|k| inside(k)).collect();
            if (pb - pa).norm() < 1e3 {
                assert_eq!(got, want, "{a:?} -> {b:?}");
            } else {
                assert!(!got.is_empty());
            }
        }
        let mut n = 0;
        walk_cells_in(
            Vector2::zeros(),
            Vector2::new(1.0, 0.0),
            cell,
            None,
            |_, _, _| {
                n += 1;
                true
            },
        );
        assert_eq!(n, 0);
    }

    /// With a grid's own probe (blocks of 32, 16, 8 and 4 cells a side, one
    /// word each, [`crate::occupancy::OccupancyProbe::empty_block`]) the walk
    /// meets every occupied cell the cell-by-cell walk meets, in the same
    /// order and with the same distances to the bit: on a map of walls and
    /// specks with holes cut out, from inside and outside it, ending in
    /// empty space and on occupied cells.
    #[test]
    fn a_grids_probe_skips_only_empty_space() {
        let mut rng = StdRng::seed_from_u64(17);
        let cell = 0.02;
        let mut grid = crate::NdtGrid::new(cell).unwrap();
        let mut pts: Vec<[f64; 2]> = Vec::new();
        for _ in 0..12 {
            // A wall of 0.5–3 m in any direction.
            let (x, y) = (rng.random_range(-4.0..4.0), rng.random_range(-4.0..4.0));
            let a: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let len = rng.random_range(0.5..3.0);
            for i in 0..(len / 0.01) as usize {
                let t = i as f64 * 0.01;
                pts.push([x + t * a.cos(), y + t * a.sin()]);
            }
        }
        for _ in 0..300 {
            pts.push([rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0)]);
        }
        grid.insert(&pts, crate::Pose2::identity()).unwrap();
        let mut keys: Vec<CellKey> = grid.keys().collect();
        keys.sort_unstable();
        let holes: Vec<CellKey> = keys.iter().copied().step_by(7).collect();
        grid.remove_cells(&holes);
        let occupied = |k: CellKey| grid.stats(k).is_some();
        let mut met_any = 0;
        for case in 0..3000 {
            let a = Vector2::new(rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0));
            // Every third segment ends on a point of the map.
            let b = if case % 3 == 0 {
                let p = pts[rng.random_range(0..pts.len())];
                Vector2::new(p[0], p[1])
            } else {
                Vector2::new(rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0))
            };
            let run = |skipping: bool| {
                let mut out = Vec::new();
                let visit = |k: CellKey, t0: f64, t1: f64| {
                    if occupied(k) {
                        out.push((k, t0.to_bits(), t1.to_bits()));
                    }
                    true
                };
                if skipping {
                    let mut probe = grid.occupancy_probe();
                    walk_cells_in_skipping(a, b, cell, grid.key_bounds(), &mut probe, visit);
                } else {
                    walk_cells_in(a, b, cell, grid.key_bounds(), visit);
                }
                out
            };
            let want = run(false);
            assert_eq!(run(true), want, "case {case}: {a:?} -> {b:?}");
            met_any += usize::from(!want.is_empty());
        }
        assert!(met_any > 1000, "{met_any} walks met an occupied cell");
    }

    /// Blocks of 8 × 8 cells, and smaller ones of 2 × 2 cells when the
    /// second rate is not 0, empty by fixed pseudo-random rules (at the
    /// rates out of 5): the walk must be exact whatever they claim.
    struct Oracle(u32, u32);

    impl Oracle {
        fn rule(bits: u32, key: CellKey, rate: u32) -> bool {
            let (bx, by) = (key.ix >> bits, key.iy >> bits);
            let h = (bx as u32)
                .wrapping_mul(0x9E37_79B9)
                .wrapping_add((by as u32).wrapping_mul(0x85EB_CA6B))
                .rotate_left(13 + bits);
            h % 5 < rate
        }
        fn empty(&self, key: CellKey) -> bool {
            Self::rule(3, key, self.0)
        }
        fn empty_inner(&self, key: CellKey) -> bool {
            Self::rule(1, key, self.1)
        }
    }

    impl EmptyBlocks for Oracle {
        fn block_bits(&self) -> Option<u32> {
            Some(3)
        }
        fn is_empty(&mut self, key: CellKey) -> bool {
            self.empty(key)
        }
        fn inner_bits(&self) -> Option<u32> {
            (self.1 > 0).then_some(1)
        }
        fn inner_is_empty(&mut self, key: CellKey) -> bool {
            self.empty_inner(key)
        }
    }

    /// Skipping empty blocks (and smaller empty blocks inside the others)
    /// visits every other cell in the same order, with the same distances to
    /// the bit, and stops where the cell-by-cell walk stops.
    #[test]
    fn skipping_empty_blocks_visits_the_other_cells_exactly() {
        let mut rng = StdRng::seed_from_u64(5);
        let mut next = move || rng.random_range(-0.5f64..0.5);
        let cell = 0.02;
        let region =
            KeyBounds::of(CellKey { ix: -900, iy: -900 }).including(CellKey { ix: 900, iy: 900 });
        let (mut skipped_any, mut skipped_inner) = (false, false);
        for case in 0..5000u32 {
            let oracle = Oracle(case / 5 % 5, case / 25 % 4);
            let mut a = Vector2::new(10.0 * next(), 10.0 * next());
            // Axis-parallel, diagonal and general directions, short and long;
            // from cell centres along slopes ±1, ±2, ±1/2, where crossings of
            // the two axes tie exactly.
            let b = match case % 5 {
                0 => a + Vector2::new(20.0 * next(), 0.0),
                1 => a + Vector2::new(0.0, 20.0 * next()),
                2 => {
                    let d = 20.0 * next();
                    a + Vector2::new(d, d)
                }
                3 => {
                    a = Vector2::new((a.x / cell).floor() + 0.5, (a.y / cell).floor() + 0.5) * cell;
                    let (sx, sy) = [
                        (1.0, 1.0),
                        (1.0, -1.0),
                        (-1.0, 2.0),
                        (2.0, -1.0),
                        (-2.0, -1.0),
                    ][case as usize / 5 % 5];
                    a + Vector2::new(sx, sy) * (cell * f64::from(30 + case % 400))
                }
                _ => Vector2::new(40.0 * next(), 40.0 * next()),
            };
            // Stop at the n-th visited cell outside the empty blocks.
            let stop_after = if case % 3 == 0 {
                1 + case as usize % 40
            } else {
                usize::MAX
            };
            // Cells in an empty block, the end's included, are not visited.
            let keep = |k: &CellKey| !(oracle.empty(*k) || oracle.1 > 0 && oracle.empty_inner(*k));
            let run = |skip: &mut dyn FnMut() -> Option<Oracle>| {
                let mut out = Vec::new();
                let mut n = 0;
                let mut visit = |k: CellKey, t0: f64, t1: f64| {
                    if !keep(&k) {
                        return true;
                    }
                    out.push((k, t0.to_bits(), t1.to_bits()));
                    n += 1;
                    n < stop_after
                };
                match skip() {
                    Some(mut o) => {
                        walk_cells_in_skipping(a, b, cell, Some(region), &mut o, &mut visit)
                    }
                    None => walk_cells_in(a, b, cell, Some(region), &mut visit),
                }
                out
            };
            let want = run(&mut || None);
            let got = run(&mut || Some(Oracle(oracle.0, oracle.1)));
            assert_eq!(got, want, "case {case}: {a:?} -> {b:?}");
            skipped_any |= case / 5 % 5 > 0 && !want.is_empty();
            skipped_inner |= oracle.1 > 0 && !want.is_empty();
        }
        assert!(skipped_any && skipped_inner);
    }
}
