//! A scan's score terms (eq. 1 and 3–5) computed in blocks: first every
//! point of a block is paired with its distribution (look-ups, neighbour
//! search: branchy, short) and the pair's inputs are written column by
//! column; then the block's arithmetic runs over the columns, [`LANES`] pairs
//! at a time (mapping the point by eq. 2, `exp`, gradient, Hessian: long
//! dependency chains, no data-dependent branch), which the compiler turns
//! into SIMD instructions (AVX2 or AVX-512 where the processor has them,
//! chosen at run time).
//!
//! Each lane keeps its own running sums (pair `j` of a block goes to lane
//! `j mod LANES`); [`PairBlock::finish`] adds the lanes in order. The result
//! therefore differs from a point-by-point sum in the last bits (a different
//! summation order, and [`crate::lanexp`] instead of the C library's `exp`),
//! but not from one processor to another: no fused multiply-add is used, and
//! the order is fixed by the pairs alone.
//!
//! [`PairBlock`] queues any number of pairs per point (the 3 × 3 pairing of
//! `MatchOptions::pair_neighbors`); the matcher's usual one pair per point
//! keeps its columns between evaluations instead ([`crate::pairs`]), with the
//! same arithmetic.

use multiversion::multiversion;
use nalgebra::{Matrix3, Vector3};

use crate::cell::Gaussian;
use crate::lanexp::exp_nonpositive;
use crate::score::{Order, ScoreTerms};
use crate::se2::Pose2;

/// Pairs computed side by side (one AVX-512 register of `f64`, two of AVX2).
pub const LANES: usize = 8;
/// Chunks of [`LANES`] pairs per block.
const CHUNKS: usize = 16;

/// The inputs of [`LANES`] pairs, one array per quantity. A lane with
/// weight 0 and zeros elsewhere (padding, an unpaired point) adds exact
/// zeros whatever its point.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Chunk {
    /// Scan-frame point.
    pub x: [f64; LANES],
    pub y: [f64; LANES],
    /// `q`: the distribution's mean (map frame).
    pub mx: [f64; LANES],
    pub my: [f64; LANES],
    /// `C = Σ⁻¹` (symmetric).
    pub c00: [f64; LANES],
    pub c01: [f64; LANES],
    pub c11: [f64; LANES],
    /// Scan points the pair stands for (0 for padding).
    pub w: [f64; LANES],
    /// The distribution's surface normal ([`Gaussian::normal`]).
    pub nx: [f64; LANES],
    pub ny: [f64; LANES],
    /// 1 when the distribution is the point's own cell's, else 0.
    pub own: [f64; LANES],
}

impl Chunk {
    /// Lane `l` takes point `x` (weight `weight`) paired with `dist`.
    #[inline(always)]
    pub fn set(&mut self, l: usize, x: [f64; 2], weight: f64, dist: &Gaussian, own: bool) {
        self.x[l] = x[0];
        self.y[l] = x[1];
        self.set_pair(l, weight, dist, own);
    }

    /// Lane `l` (its point already set) is paired with `dist`.
    #[inline(always)]
    pub fn set_pair(&mut self, l: usize, weight: f64, dist: &Gaussian, own: bool) {
        let m = &dist.inverse;
        self.mx[l] = dist.mean.x;
        self.my[l] = dist.mean.y;
        self.c00[l] = m[(0, 0)];
        self.c01[l] = m[(0, 1)];
        self.c11[l] = m[(1, 1)];
        self.w[l] = weight;
        self.nx[l] = dist.normal.x;
        self.ny[l] = dist.normal.y;
        self.own[l] = if own { 1.0 } else { 0.0 };
    }

    /// Lane `l` (its point already set) has no pair: it adds exact zeros.
    #[inline(always)]
    pub fn clear_pair(&mut self, l: usize) {
        self.mx[l] = 0.0;
        self.my[l] = 0.0;
        self.c00[l] = 0.0;
        self.c01[l] = 0.0;
        self.c11[l] = 0.0;
        self.w[l] = 0.0;
        self.nx[l] = 0.0;
        self.ny[l] = 0.0;
        self.own[l] = 0.0;
    }
}

/// Rows of [`LaneSums`].
pub(crate) const SUMS: usize = 16;

/// Running sums per lane: `E`, `g₀…g₂`, `H₀₀ H₀₁ H₀₂ H₁₁ H₁₂ H₂₂`, and the
/// point-to-plane information of own-cell pairs `A₀₀ A₀₁ A₀₂ A₁₁ A₁₂ A₂₂`.
pub(crate) type LaneSums = [[f64; LANES]; SUMS];

/// The terms of lane sums `sums`, the lanes added in order; `matched` is the
/// caller's count of points that had a distribution.
pub(crate) fn pass_terms(sums: &LaneSums, matched: usize) -> PassTerms {
    let total = sums.map(|lanes| lanes.iter().fold(0.0, |a, v| a + v));
    let [e, g0, g1, g2, h00, h01, h02, h11, h12, h22, a00, a01, a02, a11, a12, a22] = total;
    PassTerms {
        terms: ScoreTerms {
            score: e,
            gradient: Vector3::new(g0, g1, g2),
            hessian: Matrix3::new(h00, h01, h02, h01, h11, h12, h02, h12, h22),
            matched,
        },
        information: Matrix3::new(a00, a01, a02, a01, a11, a12, a02, a12, a22),
    }
}

/// What one pass over a scan's pairs gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassTerms {
    /// Score, gradient and Hessian (eq. 1, 4, 5).
    pub terms: ScoreTerms,
    /// With [`Order::Derivatives`], the point-to-plane information
    /// `Σ Jᵢᵀ nᵢ nᵢᵀ Jᵢ` of the points paired with their own cell's
    /// distribution (what [`crate::information::point_to_plane_information`]
    /// gives for [`crate::information::own_cell_pairs`]; each point counts
    /// once, whatever its weight); zero with [`Order::Value`].
    pub information: Matrix3<f64>,
}

/// One block of pairs waiting for their arithmetic, and the lane sums of
/// the blocks before it.
pub struct PairBlock {
    chunks: [Chunk; CHUNKS],
    len: usize,
    sums: LaneSums,
}

impl Default for PairBlock {
    fn default() -> Self {
        Self {
            chunks: [Chunk::default(); CHUNKS],
            len: 0,
            sums: [[0.0; LANES]; SUMS],
        }
    }
}

/// What the arithmetic needs besides the pairs.
#[derive(Clone, Copy)]
pub struct Scan {
    /// The pose the points are mapped with (eq. 2).
    pub pose: Pose2,
    /// `(sin θ, cos θ)` of the pose.
    pub sin_cos: (f64, f64),
    /// How much of the expansion to accumulate.
    pub order: Order,
}

impl Scan {
    /// The arithmetic's inputs for `pose`.
    pub fn new(pose: Pose2, order: Order) -> Self {
        Self {
            pose,
            sin_cos: pose.theta.sin_cos(),
            order,
        }
    }

    /// Adds the terms of `chunks` to `sums` (see [`add_chunks`]).
    pub(crate) fn add(&self, chunks: &[Chunk], sums: &mut LaneSums) {
        let (s, c) = self.sin_cos;
        add_chunks(
            chunks,
            [s, c, self.pose.x, self.pose.y],
            self.order == Order::Derivatives,
            sums,
        );
    }
}

impl PairBlock {
    /// Queues scan point `x`, standing for `weight` points (1 for a point;
    /// see [`crate::reduce`]), paired with `dist`, which is its own cell's
    /// when `own`; runs the block first when it is full.
    #[inline]
    pub fn push(&mut self, x: [f64; 2], weight: f64, dist: &Gaussian, own: bool, scan: &Scan) {
        if self.len == LANES * CHUNKS {
            self.flush(scan);
        }
        let (c, l) = (self.len / LANES, self.len % LANES);
        let Some(ch) = self.chunks.get_mut(c) else {
            return;
        };
        ch.set(l, x, weight, dist, own);
        self.len += 1;
    }

    /// Adds the queued pairs to the lane sums and empties the block.
    fn flush(&mut self, scan: &Scan) {
        let used = self.len.div_ceil(LANES);
        // Padding pairs weigh 0 and add exact zeros.
        if let Some(last) = self.chunks.get_mut(self.len / LANES) {
            for l in self.len % LANES..LANES {
                last.x[l] = 0.0;
                last.y[l] = 0.0;
                last.clear_pair(l);
            }
        }
        let chunks = self.chunks.get(..used).unwrap_or(&[]);
        scan.add(chunks, &mut self.sums);
        self.len = 0;
    }

    /// The terms of every pair pushed, the lanes summed in order; `matched`
    /// is the caller's count of points that had a distribution. Leaves the
    /// block empty, as new.
    pub fn finish(&mut self, scan: &Scan, matched: usize) -> PassTerms {
        self.flush(scan);
        let terms = pass_terms(&self.sums, matched);
        self.sums = [[0.0; LANES]; SUMS];
        terms
    }
}

/// Adds the terms of `chunks` to `sums`, lane by lane: the expressions of
/// [`crate::score::Accumulator::add`] (eq. 1, 4, 5), with a pair whose term
/// underflows (or is NaN) adding zeros. `pose`: `sin θ, cos θ, tx, ty`; a
/// point is mapped by eq. (2) with the expression of
/// [`Pose2::transform_with`] (the same bits).
#[multiversion(targets(
    "x86_64+avx512f+avx512dq+avx512vl+avx2+fma+avx",
    "x86_64+avx2+fma+avx",
    "aarch64+neon"
))]
fn add_chunks(chunks: &[Chunk], pose: [f64; 4], derivatives: bool, sums: &mut LaneSums) {
    let [sn, cs, tx, ty] = pose;
    for ch in chunks {
        let mut s = [0.0; LANES];
        let mut cd0 = [0.0; LANES];
        let mut cd1 = [0.0; LANES];
        let mut c00 = [0.0; LANES];
        let mut c01 = [0.0; LANES];
        let mut c11 = [0.0; LANES];
        for l in 0..LANES {
            // eq. (2), then d = x' − q.
            let (x, y) = (ch.x[l], ch.y[l]);
            let dx = cs * x - sn * y + tx - ch.mx[l];
            let dy = sn * x + cs * y + ty - ch.my[l];
            let a0 = ch.c00[l] * dx + ch.c01[l] * dy;
            let a1 = ch.c01[l] * dx + ch.c11[l] * dy;
            let e = dx * a0 + dy * a1;
            // eq. (1): one point's contribution.
            let v = exp_nonpositive(-0.5 * e);
            // A pair whose term underflows or is NaN adds exact zeros (its
            // inputs are zeroed too: 0 · ∞ would be NaN).
            let keep = v > 0.0;
            s[l] = if keep { ch.w[l] * v } else { 0.0 };
            cd0[l] = if keep { a0 } else { 0.0 };
            cd1[l] = if keep { a1 } else { 0.0 };
            c00[l] = if keep { ch.c00[l] } else { 0.0 };
            c01[l] = if keep { ch.c01[l] } else { 0.0 };
            c11[l] = if keep { ch.c11[l] } else { 0.0 };
        }
        for (acc, v) in sums[0].iter_mut().zip(s) {
            *acc += v;
        }
        if !derivatives {
            continue;
        }
        for l in 0..LANES {
            let (x, y) = (ch.x[l], ch.y[l]);
            let a = -x * sn - y * cs;
            let b = x * cs - y * sn;
            // u_k = dᵀ C J_k
            let u = [cd0[l], cd1[l], cd0[l] * a + cd1[l] * b];
            // J_lᵀ C J_k
            let m02 = c00[l] * a + c01[l] * b;
            let m12 = c01[l] * a + c11[l] * b;
            let m22 = a * m02 + b * m12;
            // dᵀ C ∂²x'/∂θ²
            let second = cd0[l] * (-x * cs + y * sn) + cd1[l] * (-x * sn - y * cs);
            let sl = s[l];
            sums[1][l] += u[0] * sl;
            sums[2][l] += u[1] * sl;
            sums[3][l] += u[2] * sl;
            sums[4][l] += (c00[l] - u[0] * u[0]) * sl;
            sums[5][l] += (c01[l] - u[0] * u[1]) * sl;
            sums[6][l] += (m02 - u[0] * u[2]) * sl;
            sums[7][l] += (c11[l] - u[1] * u[1]) * sl;
            sums[8][l] += (m12 - u[1] * u[2]) * sl;
            sums[9][l] += (m22 + second - u[2] * u[2]) * sl;
            // Point-to-plane information (crate::information): Jᵀn of own-cell
            // pairs, whatever their term.
            let (nx, ny, o) = (ch.nx[l], ch.ny[l], ch.own[l]);
            let j2 = nx * a + ny * b;
            sums[10][l] += o * (nx * nx);
            sums[11][l] += o * (nx * ny);
            sums[12][l] += o * (nx * j2);
            sums[13][l] += o * (ny * ny);
            sums[14][l] += o * (ny * j2);
            sums[15][l] += o * (j2 * j2);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::Accumulator;
    use nalgebra::{Matrix2, Vector2};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Most pairs one point adds (the 3 × 3 block of
    /// [`crate::matcher::MatchOptions::pair_neighbors`]).
    const MAX_PAIRS_PER_POINT: usize = 9;

    fn close(a: f64, b: f64, scale: f64) -> bool {
        (a - b).abs() <= 1e-13 * scale
    }

    /// Block by block, in lanes, gives the terms of point-by-point
    /// accumulation with the C library's `exp` to within 1e-13 of the
    /// summed magnitudes: across block boundaries, with several pairs per
    /// point, with weights, and with pairs far enough out to underflow.
    #[test]
    fn matches_point_by_point() {
        let mut rng = StdRng::seed_from_u64(11);
        let mut next = move || rng.random_range(-0.5f64..0.5);
        let dists: Vec<Gaussian> = (0..40)
            .map(|i| {
                // Every tenth distribution so narrow that most terms underflow.
                let k = if i % 10 == 0 { 1e5 } else { 1.0 };
                let a = k * (400.0 + 300.0 * next());
                let b = k * (900.0 + 600.0 * next());
                let c = k * 100.0 * next();
                Gaussian {
                    mean: Vector2::new(next(), next()),
                    inverse: Matrix2::new(a, c, c, b),
                    normal: Vector2::new(1.0, 0.0),
                }
            })
            .collect();
        let points: Vec<[f64; 2]> = (0..700).map(|_| [next(), next()]).collect();
        let weights: Vec<f64> = (0..700).map(|_| 1.0 + next()).collect();
        let pose = Pose2::new(0.01, -0.02, 0.3);
        let sin_cos = pose.theta.sin_cos();
        for order in [Order::Value, Order::Derivatives] {
            for w in [None, Some(weights.as_slice())] {
                let scan = Scan::new(pose, order);
                let mut naive = Accumulator::default();
                // Σ |term| per entry: the scale of the rounding differences.
                let mut magnitude = ScoreTerms::default();
                let mut block = PairBlock::default();
                let mut pairs = 0;
                let mut own_pairs = Vec::new();
                for (i, p) in points.iter().enumerate() {
                    let x = Vector2::new(p[0], p[1]);
                    let xw = pose.transform_with(sin_cos, x);
                    // 1 to MAX_PAIRS_PER_POINT pairs per point.
                    for j in 0..=(i % MAX_PAIRS_PER_POINT) {
                        let g = &dists[(i * 7 + j) % dists.len()];
                        let wi = w.map_or(1.0, |w| w[i]);
                        naive.add(x, xw, sin_cos, g, wi, order);
                        let mut one = Accumulator::default();
                        one.add(x, xw, sin_cos, g, wi, order);
                        let one = one.finish();
                        magnitude.score += one.score.abs();
                        magnitude.gradient += one.gradient.abs();
                        magnitude.hessian += one.hessian.abs();
                        block.push(*p, wi, g, j == 0, &scan);
                        if j == 0 {
                            own_pairs.push((x, g));
                        }
                        pairs += 1;
                    }
                }
                assert!(pairs > LANES * CHUNKS * 3);
                let (a, m) = (naive.finish(), magnitude);
                let pass = block.finish(&scan, a.matched);
                let b = pass.terms;
                assert!(close(a.score, b.score, m.score), "{a:?} vs {b:?}");
                for k in 0..3 {
                    assert!(close(a.gradient[k], b.gradient[k], m.gradient[k]));
                    for l in 0..3 {
                        assert!(close(
                            a.hessian[(k, l)],
                            b.hessian[(k, l)],
                            m.hessian[(k, l)]
                        ));
                    }
                }
                if order == Order::Value {
                    assert_eq!(b.gradient, Vector3::zeros());
                    assert_eq!(pass.information, Matrix3::zeros());
                } else {
                    assert!(b.hessian[(2, 2)] != 0.0);
                    // The information of the own-cell pairs only, unweighted.
                    let want = crate::information::point_to_plane_information(
                        own_pairs.iter().map(|&(x, g)| (x, *g)),
                        pose,
                    );
                    let scale = want.abs().max();
                    assert!(
                        (pass.information - want).abs().max() <= 1e-13 * scale,
                        "{} vs {want}",
                        pass.information
                    );
                }
            }
        }
    }

    /// A pair whose term underflows, or whose inverse covariance is so
    /// large that the exponent is ∞ or NaN, adds exact zeros (no NaN from
    /// 0 · ∞): the same bits as a padding pair of weight 0 in its lane.
    #[test]
    fn dropped_pairs_add_exact_zeros() {
        let g = Gaussian {
            mean: Vector2::new(0.1, -0.2),
            inverse: Matrix2::new(500.0, 20.0, 20.0, 800.0),
            normal: Vector2::new(1.0, 0.0),
        };
        let huge = Gaussian {
            inverse: Matrix2::new(f64::INFINITY, 0.0, 0.0, f64::INFINITY),
            ..g
        };
        let far = Gaussian {
            inverse: Matrix2::new(1e9, 0.0, 0.0, 1e9),
            ..g
        };
        let scan = Scan::new(Pose2::new(0.0, 0.0, 0.1), Order::Derivatives);
        let pts: Vec<[f64; 2]> = (0..2 * LANES).map(|i| [0.01 * i as f64, 0.3]).collect();
        let mut with_bad = PairBlock::default();
        let mut with_zero = PairBlock::default();
        for (i, p) in pts.iter().enumerate() {
            match i % 3 {
                0 => {
                    let bad = if i % 2 == 0 { &huge } else { &far };
                    with_bad.push(*p, 1.0, bad, true, &scan);
                    with_zero.push(*p, 0.0, &g, true, &scan);
                }
                _ => {
                    with_bad.push(*p, 1.0, &g, true, &scan);
                    with_zero.push(*p, 1.0, &g, true, &scan);
                }
            }
        }
        let (a, b) = (
            with_bad.finish(&scan, 0).terms,
            with_zero.finish(&scan, 0).terms,
        );
        assert!(a.score > 0.0 && a.hessian.iter().all(|v| v.is_finite()));
        assert_eq!(a, b);
    }
}
