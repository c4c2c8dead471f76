//! Cell shapes from the pyramid: a fine cell's distribution takes its own
//! mean and the covariance of the coarser cell that holds it.
//!
//! With 2 cm cells and a 1-2 cm σ floor every cell's own covariance (eq. 7) is
//! below the floor, so its distribution is an isotropic blob around where one
//! scan happened to sample a surface. Matched against such blobs, a scan is
//! pulled towards the other scan's sample positions along a wall as much as
//! onto the wall; in a corridor, where the samples move with the robot, that
//! biases the estimated motion towards zero. The pyramid (exact sums of the
//! fine cells) gives every fine cell the orientation and spread of the wall
//! segment it lies on at no extra storage: with [`Shape`] a cell finer than
//! the shape scale keeps its own 2 cm-precise mean but the covariance of its
//! ancestor at that scale (default 32 cm, see `MatchOptions::shape_cell`), so
//! it constrains the scan across the wall and hardly along it. Cells whose
//! ancestor holds fewer than 3 points keep the paper's distribution (eq. 7,
//! fusion of §IV-A(3)).

use rustc_hash::{FxHashMap, FxHashSet};

use crate::cell::CellStats;
use crate::key::CellKey;
use crate::pyramid::coarse_key;

/// The ancestors a level's distributions take their covariance from.
#[derive(Debug, Clone, Copy)]
pub struct Shape<'a> {
    /// The cells of the shape level (sums about their centres).
    pub cells: &'a FxHashMap<CellKey, CellStats>,
    /// Levels between the distributions' level and the shape level (≥ 1).
    pub depth: usize,
}

impl<'a> Shape<'a> {
    /// Every occupied cell of `cells` (the distributions' level) under one of
    /// `ancestors` (keys of the shape level): their distributions change with
    /// the ancestor. Each cell once (a cell has one ancestor), in no
    /// particular order.
    pub fn descendants(
        &self,
        cells: &FxHashMap<CellKey, CellStats>,
        ancestors: &FxHashSet<CellKey>,
    ) -> Vec<CellKey> {
        let side = 1u64 << self.depth.min(31);
        let lookups = (side * side).saturating_mul(ancestors.len() as u64);
        if lookups >= cells.len() as u64 {
            // Cheaper to test every cell of the level once.
            return cells
                .keys()
                .filter(|&&k| ancestors.contains(&coarse_key(k, self.depth)))
                .copied()
                .collect();
        }
        let mut out = Vec::with_capacity(ancestors.len() * 16);
        let side = side as i32; // < 2^16 here: side² < cells.len()
        for a in ancestors {
            // The ancestor's square of `side × side` cells on this level.
            let (x0, y0) = (a.ix << self.depth, a.iy << self.depth);
            for dy in 0..side {
                for dx in 0..side {
                    let k = CellKey {
                        ix: x0 + dx,
                        iy: y0 + dy,
                    };
                    if cells.contains_key(&k) {
                        out.push(k);
                    }
                }
            }
        }
        out
    }
}
