//! A scan's points paired with one level's distributions, kept from one
//! evaluation of the score to the next (a correspondence cache).
//!
//! Newton's method (§III-A) evaluates eq. (1) and its derivatives (eq. 3–5)
//! at a sequence of nearby poses, and between two of them most points stay
//! in their cell, so they pair with the same distribution. [`ScanPairs`]
//! keeps each point's cell and its pair's inputs in the column layout of
//! [`crate::batch`] (point `i` in lane `i mod LANES` of chunk `i / LANES`).
//! An evaluation maps every point (eq. 2) and looks up only those whose cell
//! changed, and those whose own cell has no distribution: the neighbour
//! search of §IV-A(1) picks the nearest mean to where the point is, so they
//! are paired anew every time. The arithmetic then runs over the kept
//! columns in place, with no copy.
//!
//! A kept pair is exactly the pair a fresh look-up gives (the same cell of
//! the same distributions), and every point has its own lane whether it is
//! paired or not (an unpaired point weighs 0 and adds exact zeros), so an
//! evaluation gives the same bits whatever was kept before it.

use std::borrow::Borrow;
use std::cell::RefCell;

use multiversion::multiversion;
use nalgebra::Vector2;

use crate::batch::{pass_terms, Chunk, LaneSums, PassTerms, Scan, LANES, SUMS};
use crate::distributions::{CursorVisitor, DistLookup, Distributions};
use crate::key::CellKey;
use crate::neighbor::nearest_in_rings_counted;
use crate::score::Order;
use crate::se2::Pose2;

/// The cells of one chunk's [`LANES`] points.
#[derive(Debug, Clone, Copy, Default)]
struct KeyLanes {
    ix: [i32; LANES],
    iy: [i32; LANES],
}

/// What is known of the pairs of one chunk's points, a bit per lane, for
/// the lane's kept key.
#[derive(Debug, Clone, Copy, Default)]
struct Known {
    /// The lane's pair (or its having none) holds wherever in that cell
    /// the point is: its own cell's distribution, or the neighbour search's
    /// result when the ring it came from holds at most one distribution.
    fixed: u8,
    /// The cell has no distribution (the neighbour search pairs the lane).
    searched: u8,
    /// The lane holds a pair.
    paired: u8,
}

/// The points of a scan (optionally weighted, see [`crate::reduce`]) with
/// their pairs in one [`Distributions`] (see the module docs).
#[derive(Debug)]
pub struct ScanPairs<'a> {
    points: &'a [[f64; 2]],
    weights: Option<&'a [f64]>,
    /// The address of the distributions the kept pairs come from (an
    /// identity only; they outlive the pairs).
    source: Option<usize>,
    store: Storage,
}

/// The vectors of a [`ScanPairs`]. A dropped one's go to the next one made
/// on the same thread: the odometry loop makes 8 a scan, and each
/// allocation on its thread may wait for the allocator's lock while the
/// mapper's helper holds it (glibc; benches/SPEED_LOG.md, session 26).
#[derive(Debug, Default)]
struct Storage {
    chunks: Vec<Chunk>,
    keys: Vec<KeyLanes>,
    known: Vec<Known>,
    /// This evaluation's cells, and per chunk the lanes whose cell exists
    /// (a point within the grid's index range) and is the kept one.
    fresh: Vec<KeyLanes>,
    valid: Vec<u8>,
    same: Vec<u8>,
}

impl Storage {
    /// A spare of this thread's, or a new one.
    fn spare() -> Self {
        let spare = SPARE.try_with(|s| s.try_borrow_mut().ok()?.pop());
        spare.ok().flatten().unwrap_or_default()
    }

    /// `n` chunks of each, keeping what a previous use left: each column
    /// is written before it is read, so the results are those of new
    /// vectors. [`ScanPairs::set_points`] writes every point and clears the
    /// padding lanes' pairs; the first evaluation empties `known` (nothing
    /// is paired yet), so every point's lane has its pair and kept key
    /// written; `cell_keys` writes `fresh`, `valid` and `same`. Zeroing the
    /// chunks instead took 4.7 % of the loop's instructions (benches/SPEED_LOG.md,
    /// session 27).
    ///
    /// A vector too short grows to `n` exactly, not by doubling: a spare
    /// reused for a slightly larger scan (a match's pairs of all its points
    /// and of its rotated starts' fewer points take turns with the spares)
    /// would otherwise pass [`SPARE_CHUNKS`] at scans of 2048–4096 points
    /// and be freed at the match's end. With two threads matching at once,
    /// glibc then handed the freed memory back to the kernel and took it
    /// again about once every three matches (`madvise`, a TLB shootdown on
    /// the other CPU, page faults): two Python threads matching 3600-point
    /// scans of one small map took 1.30× one thread's CPU time, 1.00× with
    /// exact growth (benches/SPEED_LOG.md, session 68).
    fn sized(mut self, n: usize) -> Self {
        fn exactly<T: Clone>(v: &mut Vec<T>, n: usize, fill: T) {
            v.reserve_exact(n.saturating_sub(v.len()));
            // `resize` keeps the first `n` as they are (truncating any more).
            v.resize(n, fill);
        }
        exactly(&mut self.chunks, n, Chunk::default());
        exactly(&mut self.keys, n, KeyLanes::default());
        exactly(&mut self.known, n, Known::default());
        exactly(&mut self.fresh, n, KeyLanes::default());
        exactly(&mut self.valid, n, 0);
        exactly(&mut self.same, n, 0);
        self
    }
}

/// Storages a thread keeps at most.
const SPARE_STORAGES: usize = 8;

/// Chunks a kept storage holds at most: those of the largest scan whose
/// pairs a match keeps ([`crate::matcher::KEPT_MAX_POINTS`], 4096 points,
/// 512 chunks, about 0.5 MB; the Intel log's scans take 23), so that no
/// match's storage is freed at its end (a larger scan goes through
/// [`evaluate_streaming`]'s block); a thread keeps at most
/// `SPARE_STORAGES` of them.
const SPARE_CHUNKS: usize = crate::matcher::KEPT_MAX_POINTS.div_ceil(LANES);

thread_local! {
    static SPARE: RefCell<Vec<Storage>> = const { RefCell::new(Vec::new()) };
}

/// Its vectors go back to the thread's spares (`Storage`, above).
impl Drop for ScanPairs<'_> {
    fn drop(&mut self) {
        if self.store.chunks.capacity() > SPARE_CHUNKS {
            return;
        }
        let storage = std::mem::take(&mut self.store);
        // A thread being torn down keeps nothing.
        let _ = SPARE.try_with(|s| {
            if let Ok(mut spare) = s.try_borrow_mut() {
                if spare.len() < SPARE_STORAGES {
                    spare.push(storage);
                }
            }
        });
    }
}

impl<'a> ScanPairs<'a> {
    /// `points` (scan frame \[m\]), each standing for `weights[i]` points (1
    /// without weights), with nothing paired yet.
    pub fn new(points: &'a [[f64; 2]], weights: Option<&'a [f64]>) -> Self {
        let n = points.len().div_ceil(LANES);
        let mut pairs = Self {
            points,
            weights,
            source: None,
            store: Storage::spare().sized(n),
        };
        pairs.set_points(points, weights);
        pairs
    }

    /// The chunks take `points` (at most as many as at [`ScanPairs::new`];
    /// any more are left out) with nothing paired: padding lanes at the
    /// origin with no pair (they add exact zeros); the points' lanes keep
    /// their old pairs' columns, which the next evaluation writes, as it
    /// knows of no pair (`source` is reset).
    fn set_points(&mut self, points: &'a [[f64; 2]], weights: Option<&'a [f64]>) {
        let n = points.len().div_ceil(LANES).min(self.store.keys.len());
        self.points = points
            .get(..(n * LANES).min(points.len()))
            .unwrap_or(points);
        self.weights = weights;
        self.source = None;
        self.store.chunks.truncate(n);
        for (c, ch) in self.store.chunks.iter_mut().enumerate() {
            for l in 0..LANES {
                match self.points.get(c * LANES + l) {
                    Some(p) => {
                        ch.x[l] = p[0];
                        ch.y[l] = p[1];
                    }
                    None => {
                        ch.x[l] = 0.0;
                        ch.y[l] = 0.0;
                        ch.clear_pair(l);
                    }
                }
            }
        }
    }

    /// Score terms of the points at `pose` against `dists` (cells of
    /// `1 / inv_cell` m), each paired with its own cell's distribution or,
    /// when `search_radius` is given and that cell has none, the nearest
    /// found by [`crate::neighbor::nearest_in_rings_with`]. Pairs kept from
    /// an evaluation against other distributions are forgotten first.
    pub fn evaluate(
        &mut self,
        dists: &Distributions,
        pose: Pose2,
        inv_cell: f64,
        search_radius: Option<u32>,
        order: Order,
    ) -> PassTerms {
        let scan = Scan::new(pose, order);
        let mut sums: LaneSums = [[0.0; LANES]; SUMS];
        let matched = self.accumulate(dists, &scan, inv_cell, search_radius, &mut sums);
        pass_terms(&sums, matched)
    }

    /// The terms of [`ScanPairs::evaluate`] added to `sums` (lane by lane,
    /// chunk after chunk); returns the number of points paired.
    fn accumulate(
        &mut self,
        dists: &Distributions,
        scan: &Scan,
        inv_cell: f64,
        search_radius: Option<u32>,
        sums: &mut LaneSums,
    ) -> usize {
        let source = std::ptr::from_ref(dists) as usize;
        if self.source != Some(source) {
            self.store.known.fill(Known::default());
            self.source = Some(source);
        }
        let (s, c) = scan.sin_cos;
        cell_keys(
            &self.store.chunks,
            [s, c, scan.pose.x, scan.pose.y, inv_cell],
            &self.store.keys,
            &mut self.store.fresh,
            &mut self.store.valid,
            &mut self.store.same,
        );
        let matched = dists.visit(Refresh {
            pairs: self,
            scan,
            search_radius,
        });
        scan.add(&self.store.chunks, sums);
        matched
    }
}

/// Points of a block of [`evaluate_streaming`] (a multiple of [`LANES`];
/// smaller in the tests, so that their scans take several blocks).
#[cfg(not(test))]
const STREAM_BLOCK: usize = 256;
#[cfg(test)]
const STREAM_BLOCK: usize = 64;

/// [`ScanPairs::evaluate`] with nothing kept, for a scan whose kept pairs
/// would not fit in the processor's caches (their columns take about 100
/// bytes a point): the points go through one small [`ScanPairs`] a block at
/// a time. The lanes and their order are those of one [`ScanPairs`] over all
/// the points (blocks are whole chunks), so the terms are the same bits.
pub fn evaluate_streaming(
    dists: &Distributions,
    points: &[[f64; 2]],
    weights: Option<&[f64]>,
    pose: Pose2,
    inv_cell: f64,
    search_radius: Option<u32>,
    order: Order,
) -> PassTerms {
    let scan = Scan::new(pose, order);
    let mut sums: LaneSums = [[0.0; LANES]; SUMS];
    let mut matched = 0;
    let mut pairs: Option<ScanPairs<'_>> = None;
    for (i, block) in points.chunks(STREAM_BLOCK).enumerate() {
        let w = chunk_weights(weights, i, STREAM_BLOCK, block.len());
        // The first block sizes the storage; the next ones reuse it.
        let p = match pairs.as_mut() {
            Some(p) => {
                p.set_points(block, w);
                p
            }
            None => pairs.insert(ScanPairs::new(block, w)),
        };
        matched += p.accumulate(dists, &scan, inv_cell, search_radius, &mut sums);
    }
    pass_terms(&sums, matched)
}

/// The weights of chunk `index` (of `size` points; this one `len`) of a
/// scan's points, if the scan has weights.
#[inline]
pub fn chunk_weights(
    weights: Option<&[f64]>,
    index: usize,
    size: usize,
    len: usize,
) -> Option<&[f64]> {
    weights.and_then(|w| w.get(index * size..index * size + len))
}

/// The cell of every point at a pose (`sin θ, cos θ, tx, ty`, then `1 /
/// cell size`): into `fresh`, with per chunk the lanes whose cell exists
/// (`valid`: as [`CellKey::of`] gives `Some`, the same index) and the valid
/// lanes whose cell is the kept one in `kept` (`same`). No branch: the
/// compiler vectorises it.
#[multiversion(targets(
    "x86_64+avx512f+avx512dq+avx512vl+avx2+fma+avx",
    "x86_64+avx2+fma+avx",
    "aarch64+neon"
))]
fn cell_keys(
    chunks: &[Chunk],
    pose: [f64; 5],
    kept: &[KeyLanes],
    fresh: &mut [KeyLanes],
    valid: &mut [u8],
    same: &mut [u8],
) {
    let [sn, cs, tx, ty, inv] = pose;
    let rows = chunks
        .iter()
        .zip(kept)
        .zip(fresh.iter_mut().zip(valid.iter_mut().zip(same.iter_mut())));
    for ((ch, kept), (fresh, (valid, same))) in rows {
        let mut ok = [false; LANES];
        let mut eq = [false; LANES];
        for l in 0..LANES {
            let (x, y) = (ch.x[l], ch.y[l]);
            // eq. (2) as Pose2::transform_with, then the cell (lanes out of
            // range are not valid anyway).
            let w = Vector2::new(cs * x - sn * y + tx, sn * x + cs * y + ty);
            let (key, valid) = CellKey::of_flagged_in_lanes(w, inv);
            ok[l] = valid;
            fresh.ix[l] = key.ix;
            fresh.iy[l] = key.iy;
            eq[l] = key.ix == kept.ix[l] && key.iy == kept.iy[l];
        }
        let (mut v, mut e) = (0u8, 0u8);
        for l in 0..LANES {
            v |= u8::from(ok[l]) << l;
            e |= u8::from(ok[l] && eq[l]) << l;
        }
        *valid = v;
        *same = e;
    }
}

/// One evaluation's pairing, run with the distributions' reader of
/// whichever kind (see [`Distributions::visit`]): returns the number of
/// points paired.
struct Refresh<'p, 'a> {
    pairs: &'p mut ScanPairs<'a>,
    scan: &'p Scan,
    search_radius: Option<u32>,
}

impl CursorVisitor for Refresh<'_, '_> {
    type Out = usize;

    fn visit<L: DistLookup>(self, mut cursor: L) -> usize {
        let ScanPairs {
            points,
            weights,
            store:
                Storage {
                    chunks,
                    keys,
                    known,
                    fresh,
                    valid,
                    same,
                },
            ..
        } = self.pairs;
        let (pose, sin_cos) = (self.scan.pose, self.scan.sin_cos);
        let mut matched = 0;
        let rows = chunks
            .iter_mut()
            .zip(keys.iter_mut().zip(known.iter_mut()))
            .zip(fresh.iter().zip(valid.iter().zip(same.iter())));
        for (c, ((ch, (kept, known)), (fresh, (&valid, &same)))) in rows.enumerate() {
            let lanes = points.len().saturating_sub(c * LANES).min(LANES);
            let all = if lanes == LANES {
                u8::MAX
            } else {
                (1u8 << lanes) - 1
            };
            // The lanes whose pair is kept: nothing to do.
            let hit = same & known.fixed;
            matched += (hit & known.paired).count_ones() as usize;
            if hit == all {
                continue;
            }
            for l in 0..lanes {
                let bit = 1u8 << l;
                if hit & bit != 0 {
                    continue;
                }
                known.fixed &= !bit;
                known.paired &= !bit;
                if valid & bit == 0 {
                    known.searched &= !bit;
                    ch.clear_pair(l);
                    continue;
                }
                let i = c * LANES + l;
                let key = CellKey {
                    ix: fresh.ix[l],
                    iy: fresh.iy[l],
                };
                let w = weights.and_then(|w| w.get(i)).copied().unwrap_or(1.0);
                if same & known.searched & bit == 0 {
                    kept.ix[l] = key.ix;
                    kept.iy[l] = key.iy;
                    if let Some(g) = cursor.get(key) {
                        ch.set_pair(l, w, g.borrow(), true);
                        known.searched &= !bit;
                        known.fixed |= bit;
                        known.paired |= bit;
                        matched += 1;
                        continue;
                    }
                    known.searched |= bit;
                }
                let Some(p) = points.get(i) else {
                    break;
                };
                let xw = pose.transform_with(sin_cos, Vector2::new(p[0], p[1]));
                let (g, candidates) = match self.search_radius {
                    Some(r) => nearest_in_rings_counted(&mut cursor, xw, key, r),
                    None => (None, 0),
                };
                if candidates <= 1 {
                    known.fixed |= bit;
                }
                match g {
                    Some(g) => {
                        ch.set_pair(l, w, g.borrow(), false);
                        known.paired |= bit;
                        matched += 1;
                    }
                    None => ch.clear_pair(l),
                }
            }
        }
        matched
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::batch::PairBlock;
    use crate::distributions::DistOptions;
    use crate::grid::NdtGrid;
    use crate::key::MAX_INDEX;
    use crate::neighbor::nearest_in_rings_with;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// The tests' distributions: the paper's fusion, widened by 10.
    fn wide_options() -> DistOptions {
        DistOptions {
            expansion: 10.0,
            fuse_minority: true,
            sigma_floor: 0.005,
            shape_cell: 0.0,
        }
    }

    /// A fresh block of the pairs `pair` gives, point by point in order: the
    /// reference for the kept pairs (same pairs; lanes by pair, not by point,
    /// so the sums agree to rounding, not to the bit).
    fn by_block(
        dists: &Distributions,
        points: &[[f64; 2]],
        weights: Option<&[f64]>,
        pose: Pose2,
        radius: Option<u32>,
        order: Order,
    ) -> PassTerms {
        let scan = Scan::new(pose, order);
        let inv = 1.0 / dists.cell_size();
        let mut cursor = dists.cursor();
        let mut block = PairBlock::default();
        let mut matched = 0;
        for (i, p) in points.iter().enumerate() {
            let xw = pose.transform_with(scan.sin_cos, Vector2::new(p[0], p[1]));
            let Some(key) = CellKey::of(xw, inv) else {
                continue;
            };
            let pair = match cursor.get(key) {
                Some(g) => Some((g, true)),
                None => radius
                    .and_then(|r| nearest_in_rings_with(&mut cursor, xw, key, r))
                    .map(|g| (g, false)),
            };
            if let Some((g, own)) = pair {
                let w = weights.map_or(1.0, |w| w[i]);
                block.push(*p, w, &g, own, &scan);
                matched += 1;
            }
        }
        block.finish(&scan, matched)
    }

    fn close(a: &PassTerms, b: &PassTerms) -> bool {
        let t = |p: &PassTerms| {
            let mut v = vec![p.terms.score];
            v.extend(p.terms.gradient.iter());
            v.extend(p.terms.hessian.iter());
            v.extend(p.information.iter());
            v
        };
        let (x, y) = (t(a), t(b));
        let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        a.terms.matched == b.terms.matched
            && x.iter()
                .zip(&y)
                .all(|(p, q)| (p - q).abs() <= 1e-12 * scale)
    }

    /// The vectorised cells are [`CellKey::of`]'s, on both sides of 0, at
    /// and next to integers and halves, and the lanes it refuses (beyond
    /// the index range, not finite) are the ones marked not valid.
    #[test]
    fn cell_keys_are_those_of_cell_key_of() {
        let mut rng = StdRng::seed_from_u64(3);
        let lim = f64::from(MAX_INDEX);
        let mut values: Vec<f64> = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            1.0,
            -1.0,
            0.999_999_999_999_999_9,
            -1e-300,
            1e-300,
            lim - 1.0,
            lim - 0.5,
            lim,
            -lim,
            1.0 - lim,
            1.0 - lim - 1e-6,
            2.0 * lim,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            // Beyond 2⁵² the rounding is no longer exact: not valid, and no
            // overflow in the arithmetic either.
            4.5e15,
            -4.5e15,
            9.1e15 + 3.0,
            -9.1e15 - 3.0,
            1e300,
            -1e300,
            f64::MAX,
            f64::MIN,
        ];
        for _ in 0..2000 {
            let v: f64 = rng.random_range(-1e4..1e4);
            values.extend([v, v.floor(), v.floor() + 0.5, v.floor() - 1e-12]);
        }
        for inv in [1.0, 50.0, 0.25] {
            for pair in values.chunks(2 * LANES) {
                let mut ch = Chunk::default();
                for (l, v) in pair.chunks(2).enumerate() {
                    ch.x[l] = v[0] / inv;
                    ch.y[l] = *v.get(1).unwrap_or(&0.3) / inv;
                }
                let (mut fresh, mut valid, mut same) = ([KeyLanes::default()], [0], [0]);
                let kept = [KeyLanes::default()];
                cell_keys(
                    &[ch],
                    [0.0, 1.0, 0.0, 0.0, inv],
                    &kept,
                    &mut fresh,
                    &mut valid,
                    &mut same,
                );
                for l in 0..LANES {
                    let want = CellKey::of(Vector2::new(ch.x[l], ch.y[l]), inv);
                    assert_eq!(
                        valid[0] >> l & 1 == 1,
                        want.is_some(),
                        "{} {}",
                        ch.x[l],
                        ch.y[l]
                    );
                    if let Some(k) = want {
                        assert_eq!(
                            (fresh[0].ix[l], fresh[0].iy[l]),
                            (k.ix, k.iy),
                            "{} {}",
                            ch.x[l],
                            ch.y[l]
                        );
                        assert_eq!(same[0] >> l & 1 == 1, k.ix == 0 && k.iy == 0);
                    }
                }
            }
        }
    }

    /// Pairs made from a dropped one's storage (a larger scan's, paired,
    /// with other weights) evaluate to the bits of pairs made on a thread
    /// with nothing kept; a thread keeps at most `SPARE_STORAGES`, and none
    /// larger than `SPARE_CHUNKS`.
    #[test]
    fn reused_storage_gives_the_bits_of_new_storage() {
        let mut grid = NdtGrid::new(0.02).unwrap();
        // A wall, and a short one through the origin, where the padding
        // lanes' points are.
        let wall: Vec<[f64; 2]> = (0..500)
            .map(|i| [f64::from(i) * 0.004, 0.5 + 0.002 * f64::from(i % 5)])
            .chain((0..30).map(|i| [f64::from(i) * 0.002 - 0.03, 0.002 * f64::from(i % 3)]))
            .collect();
        grid.insert(&wall, Pose2::identity()).unwrap();
        let options = wide_options();
        let d = grid.distributions(0, options).unwrap();
        let inv = 1.0 / d.cell_size();
        // Its chunk 5 paired on the short wall: the lanes that are padding
        // in the small scan's last chunk.
        let big: Vec<[f64; 2]> = (0..333)
            .map(|i| {
                if (40..48).contains(&i) {
                    [0.002 * f64::from(i - 44), 0.001]
                } else {
                    [f64::from(i) * 0.005, 0.49 + 0.001 * f64::from(i % 3)]
                }
            })
            .collect();
        let heavy: Vec<f64> = (0..333).map(|i| 2.0 + f64::from(i % 4)).collect();
        // Every third point far from the wall: no pair, so its lane must
        // add zeros whatever the storage held.
        let small: Vec<[f64; 2]> = (0..45)
            .map(|i| {
                [
                    0.3 + f64::from(i) * 0.01,
                    if i % 3 == 0 { 5.0 } else { 0.51 },
                ]
            })
            .collect();
        let pose = Pose2::new(0.003, -0.002, 0.001);
        let eval = |pts: &[[f64; 2]], order| {
            ScanPairs::new(pts, None).evaluate(&d, pose, inv, Some(2), order)
        };
        let fresh = std::thread::scope(|s| {
            s.spawn(|| [Order::Value, Order::Derivatives].map(|o| eval(&small, o)))
                .join()
                .unwrap()
        });
        for _ in 0..3 {
            let mut used = ScanPairs::new(&big, Some(&heavy));
            assert!(
                used.evaluate(&d, pose, inv, Some(2), Order::Derivatives)
                    .terms
                    .matched
                    > 0
            );
        }
        assert!(SPARE.with(|s| s.borrow().len()) > 0, "the storage was kept");
        for (o, want) in [Order::Value, Order::Derivatives].into_iter().zip(fresh) {
            assert_eq!(eval(&small, o), want);
        }
        // Bounds: many alive at once, then dropped; and one too large.
        let many: Vec<_> = (0..3 * SPARE_STORAGES)
            .map(|_| ScanPairs::new(&small, None))
            .collect();
        drop(many);
        assert_eq!(SPARE.with(|s| s.borrow().len()), SPARE_STORAGES);
        SPARE.with(|s| s.borrow_mut().clear());
        let huge = vec![[0.0, 0.0]; (SPARE_CHUNKS + 1) * LANES];
        drop(ScanPairs::new(&huge, None));
        assert_eq!(SPARE.with(|s| s.borrow().len()), 0);
    }

    /// A spare reused for a larger scan grows to that scan's chunks
    /// exactly, so scans of up to `SPARE_CHUNKS` chunks keep their storage
    /// from one match to the next instead of freeing it (by doubling, 263
    /// chunks grown to 300 would take 526, over the bound).
    #[test]
    fn a_grown_spare_stays_within_the_bound() {
        let sizes = [SPARE_CHUNKS / 2 + 7, SPARE_CHUNKS / 2 + 44, SPARE_CHUNKS];
        std::thread::spawn(move || {
            for chunks in sizes {
                let points = vec![[0.0, 0.0]; chunks * LANES];
                drop(ScanPairs::new(&points, None));
                let kept = SPARE.with(|s| {
                    s.borrow()
                        .iter()
                        .map(|st| {
                            [
                                st.chunks.capacity(),
                                st.keys.capacity(),
                                st.known.capacity(),
                                st.fresh.capacity(),
                                st.valid.capacity(),
                                st.same.capacity(),
                            ]
                        })
                        .collect::<Vec<_>>()
                });
                assert_eq!(kept, vec![[chunks; 6]], "{chunks} chunks");
            }
        })
        .join()
        .unwrap();
    }

    /// A match of the largest scan whose pairs it keeps
    /// (`KEPT_MAX_POINTS`) leaves their storage to its thread for the next
    /// match: the bound takes it.
    #[test]
    fn the_largest_kept_scan_leaves_its_storage() {
        use crate::matcher::{MatchOptions, KEPT_MAX_POINTS};
        let wall: Vec<[f64; 2]> = (0..KEPT_MAX_POINTS)
            .map(|i| [i as f64 * 0.001, 0.5 + 0.003 * (i % 4) as f64])
            .collect();
        let mut grid = NdtGrid::new(0.02).unwrap();
        grid.insert(&wall, Pose2::identity()).unwrap();
        let largest = std::thread::spawn(move || {
            let guess = Pose2::new(0.004, -0.003, 0.0);
            grid.match_scan(&wall, guess, &MatchOptions::default())
                .unwrap();
            SPARE.with(|s| s.borrow().iter().map(|st| st.chunks.capacity()).max())
        })
        .join()
        .unwrap();
        assert_eq!(largest, Some(KEPT_MAX_POINTS.div_ceil(LANES)));
    }

    /// Along a random walk of poses (points crossing cells, leaving the map,
    /// with and without the neighbour search, weighted or not, on two
    /// levels in turn), every evaluation through the kept pairs gives the
    /// bits of an evaluation with nothing kept, and the pairs a fresh
    /// point-by-point pairing gives (its sums to rounding).
    #[test]
    fn kept_pairs_give_the_bits_of_fresh_ones() {
        let mut rng = StdRng::seed_from_u64(5);
        let mut grid = NdtGrid::new(0.02).unwrap();
        let wall: Vec<[f64; 2]> = (0..400)
            .map(|i| {
                let t = f64::from(i) * 0.004;
                [t, 0.5 + 0.003 * (t * 40.0).sin()]
            })
            .chain((0..300).map(|i| [0.2 + 0.0013 * f64::from(i % 7), f64::from(i) * 0.004]))
            .collect();
        grid.insert(&wall, Pose2::identity()).unwrap();
        let options = wide_options();
        let levels: Vec<_> = (0..2)
            .map(|l| grid.distributions(l, options).unwrap())
            .collect();
        let points: Vec<[f64; 2]> = (0..203)
            .map(|i| {
                let t = f64::from(i) * 0.008;
                if i % 2 == 0 {
                    [t, 0.5]
                } else {
                    [0.2, t]
                }
            })
            .collect();
        let weights: Vec<f64> = (0..203).map(|i| 1.0 + f64::from(i % 3)).collect();
        for (radius, w) in [
            (Some(1), None),
            (None, Some(weights.as_slice())),
            (Some(3), Some(weights.as_slice())),
        ] {
            let mut kept = ScanPairs::new(&points, w);
            let mut pose = Pose2::identity();
            for step in 0..60 {
                pose = Pose2::new(
                    pose.x + rng.random_range(-0.02..0.02),
                    pose.y + rng.random_range(-0.02..0.02),
                    pose.theta + rng.random_range(-0.02..0.02),
                );
                let d = &levels[(step / 7) % 2];
                let inv = 1.0 / d.cell_size();
                for order in [Order::Value, Order::Derivatives] {
                    let got = kept.evaluate(d, pose, inv, radius, order);
                    let fresh = ScanPairs::new(&points, w).evaluate(d, pose, inv, radius, order);
                    assert_eq!(got, fresh, "step {step}");
                    // Block by block (203 points: a partial last block).
                    let streamed = evaluate_streaming(d, &points, w, pose, inv, radius, order);
                    assert_eq!(got, streamed, "step {step}");
                    let want = by_block(d, &points, w, pose, radius, order);
                    assert!(close(&got, &want), "step {step}: {got:?} vs {want:?}");
                }
            }
        }
    }
}
