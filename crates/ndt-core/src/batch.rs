//! A scan's score terms (eq. 1 and 3–5) computed in blocks: first every
//! point of a block is paired with its distribution (look-ups, neighbour
//! search: branchy, short), then the block's arithmetic runs over the pairs
//! (`exp`, gradient, Hessian: long dependency chains, no data-dependent
//! branch). Interleaved in one loop, a mispredicted look-up branch flushed
//! the out-of-order window and each point's `exp` chain ran alone; in blocks
//! the processor overlaps the chains of consecutive pairs.
//!
//! Pairs are summed in the order the interleaved loop summed them (point by
//! point, and in a point's own pairing order), so the result is the same to
//! the bit.

use nalgebra::Vector2;

use crate::cell::Gaussian;
use crate::score::{Accumulator, Order};

/// Pairs per block.
const BLOCK: usize = 128;

/// One block of pairs waiting for their arithmetic.
pub struct PairBlock<'a> {
    /// Index of the point (in the scan) of each pair.
    index: [usize; BLOCK],
    /// The point in the map frame, `x' = R(θ) x + t` (eq. 2).
    mapped: [Vector2<f64>; BLOCK],
    dist: [Option<&'a Gaussian>; BLOCK],
    len: usize,
}

impl Default for PairBlock<'_> {
    fn default() -> Self {
        Self {
            index: [0; BLOCK],
            mapped: [Vector2::zeros(); BLOCK],
            dist: [None; BLOCK],
            len: 0,
        }
    }
}

/// What the arithmetic needs besides the pairs.
#[derive(Clone, Copy)]
pub struct Scan<'s> {
    /// Scan-frame points.
    pub points: &'s [[f64; 2]],
    /// Optional weight per point (1 when `None`).
    pub weights: Option<&'s [f64]>,
    /// `(sin θ, cos θ)` of the pose.
    pub sin_cos: (f64, f64),
    /// How much of the expansion to accumulate.
    pub order: Order,
}

impl<'a> PairBlock<'a> {
    /// Queues point `index`, mapped to `mapped`, paired with `dist`; runs
    /// the block into `acc` first when it is full.
    #[inline]
    pub fn push(
        &mut self,
        index: usize,
        mapped: Vector2<f64>,
        dist: &'a Gaussian,
        scan: &Scan<'_>,
        acc: &mut Accumulator,
    ) {
        if self.len == BLOCK {
            self.flush(scan, acc);
        }
        self.index[self.len] = index;
        self.mapped[self.len] = mapped;
        self.dist[self.len] = Some(dist);
        self.len += 1;
    }

    /// Adds the queued pairs' terms to `acc`, in order, and empties the block.
    pub fn flush(&mut self, scan: &Scan<'_>, acc: &mut Accumulator) {
        let n = self.len;
        for ((&i, &xw), d) in self.index[..n]
            .iter()
            .zip(&self.mapped[..n])
            .zip(&self.dist[..n])
        {
            let Some(g) = d else { continue };
            let Some(p) = scan.points.get(i) else {
                continue;
            };
            let w = scan.weights.and_then(|w| w.get(i)).copied().unwrap_or(1.0);
            acc.add(Vector2::new(p[0], p[1]), xw, scan.sin_cos, g, w, scan.order);
        }
        self.len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix2;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Most pairs one point adds (the 3 × 3 block of
    /// [`crate::matcher::MatchOptions::pair_neighbors`]).
    const MAX_PAIRS_PER_POINT: usize = 9;

    /// Block by block gives the bits of point-by-point accumulation, across
    /// block boundaries, with several pairs per point and with weights.
    #[test]
    fn same_bits_as_point_by_point() {
        let mut rng = StdRng::seed_from_u64(11);
        let mut next = move || rng.random_range(-0.5f64..0.5);
        let dists: Vec<Gaussian> = (0..40)
            .map(|_| {
                let a = 400.0 + 300.0 * next();
                let b = 900.0 + 600.0 * next();
                let c = 100.0 * next();
                Gaussian {
                    mean: Vector2::new(next(), next()),
                    inverse: Matrix2::new(a, c, c, b),
                    normal: Vector2::new(1.0, 0.0),
                }
            })
            .collect();
        let points: Vec<[f64; 2]> = (0..700).map(|_| [next(), next()]).collect();
        let weights: Vec<f64> = (0..700).map(|_| 1.0 + next()).collect();
        let sin_cos = 0.3f64.sin_cos();
        for order in [Order::Value, Order::Derivatives] {
            for w in [None, Some(weights.as_slice())] {
                let scan = Scan {
                    points: &points,
                    weights: w,
                    sin_cos,
                    order,
                };
                let (mut naive, mut blocked) = (Accumulator::default(), Accumulator::default());
                let mut block = PairBlock::default();
                for (i, p) in points.iter().enumerate() {
                    let x = Vector2::new(p[0], p[1]);
                    let xw = Vector2::new(x.x + 0.01, x.y - 0.02);
                    // 1 to MAX_PAIRS_PER_POINT pairs per point.
                    for j in 0..=(i % MAX_PAIRS_PER_POINT) {
                        let g = &dists[(i * 7 + j) % dists.len()];
                        let wi = w.map_or(1.0, |w| w[i]);
                        naive.add(x, xw, sin_cos, g, wi, order);
                        block.push(i, xw, g, &scan, &mut blocked);
                    }
                }
                block.flush(&scan, &mut blocked);
                assert_eq!(naive.finish(), blocked.finish());
            }
        }
    }
}
