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

use rustc_hash::FxHashSet;

use crate::cell::CellStats;
use crate::key::CellKey;
use crate::pyramid::Level;
use crate::table::CellTable;

/// The ancestors a level's distributions take their covariance from.
#[derive(Debug, Clone, Copy)]
pub struct Shape<'a> {
    /// The pyramid levels from the distributions' level (first) up to the
    /// shape level (last).
    levels: &'a [Level],
    /// The shape level.
    top: &'a Level,
}

impl<'a> Shape<'a> {
    /// The shape of the first of `levels` taken from the last (consecutive
    /// pyramid levels); `None` with fewer than two levels.
    pub fn new(levels: &'a [Level]) -> Option<Self> {
        let top = levels.last().filter(|_| levels.len() >= 2)?;
        Some(Self { levels, top })
    }

    /// Levels between the distributions' level and the shape level (≥ 1).
    pub fn depth(&self) -> usize {
        self.levels.len() - 1
    }

    /// The cells of the shape level (sums about their centres).
    pub fn cells(&self) -> &'a CellTable<CellStats> {
        self.top.cells()
    }

    /// Every occupied cell of the distributions' level under one of
    /// `ancestors` (keys of the shape level), as `(ancestor, cell, its sums)`:
    /// their distributions change with the ancestor. Found by descending the
    /// pyramid from each ancestor through the occupied children only (every
    /// occupied fine cell has all its ancestors); grouped by ancestor, in Z
    /// order within one, so consecutive cells mostly share a tile of the
    /// distributions' table. Each cell once.
    pub fn descendants(
        &self,
        ancestors: &FxHashSet<CellKey>,
    ) -> Vec<(CellKey, CellKey, &'a CellStats)> {
        let depth = self.depth();
        let mut out = Vec::with_capacity(ancestors.len() * 16);
        let mut stack: Vec<(usize, CellKey)> = Vec::with_capacity(4 * depth + 1);
        for &a in ancestors {
            if !self.cells().contains(a) {
                continue;
            }
            stack.push((depth, a));
            while let Some((i, k)) = stack.pop() {
                let Some(below) = i.checked_sub(1).and_then(|b| self.levels.get(b)) else {
                    continue;
                };
                let child = |(dx, dy): (i32, i32)| CellKey {
                    ix: 2 * k.ix + dx,
                    iy: 2 * k.iy + dy,
                };
                if i == 1 {
                    for c in [(0, 0), (1, 0), (0, 1), (1, 1)].map(child) {
                        if let Some(stats) = below.cells().get(c) {
                            out.push((a, c, stats));
                        }
                    }
                } else {
                    // Pushed in reverse: visited (0,0), (1,0), (0,1), (1,1).
                    for c in [(1, 1), (0, 1), (1, 0), (0, 0)].map(child) {
                        if below.cells().contains(c) {
                            stack.push((i - 1, c));
                        }
                    }
                }
            }
        }
        out
    }
}
