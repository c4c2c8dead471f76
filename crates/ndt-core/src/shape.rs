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

use crate::cell::{CellStats, Gaussian};
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

/// What an ancestor gives as a shape ([`Gaussian::shape_of`] of its sums:
/// `None` below [`crate::cell::MIN_POINTS`] points, `Some(None)` without a
/// finite distribution).
pub type AncestorShape = Option<Option<Gaussian>>;

/// The shapes of the ancestors one insert or removal touched, kept while the
/// prepared distributions are brought up to date: every level finer than the
/// shape cell takes its shapes from the same shape level, so without it each
/// touched ancestor's shape would be computed once per level.
///
/// A level's update meets the touched ancestors in the order their keys
/// first occur among its own touched cells, which for every level is the
/// order of the shape level's own touched keys (each level's are its
/// children's parents in order of first occurrence). So the first level to
/// ask computes and keeps the shapes in that order, and the others read them
/// back in step; an ancestor met out of step is computed afresh (never by
/// these updates, but the result does not depend on it).
#[derive(Debug, Default)]
pub struct ShapeMemo {
    /// Per shape level and options: the shapes in the order computed.
    runs: Vec<(RunKey, Vec<(CellKey, AncestorShape)>)>,
}

/// Empty, as the memo is between updates, with the original's storage: a
/// copy's first updates then reuse it as the original's would
/// (the `spare` module).
impl Clone for ShapeMemo {
    fn clone(&self) -> Self {
        let mut runs = Vec::with_capacity(self.runs.capacity());
        runs.extend(
            self.runs
                .iter()
                .map(|(key, shapes)| (*key, Vec::with_capacity(shapes.capacity()))),
        );
        Self { runs }
    }
}

/// A shape level and the options its shapes depend on: its cell size, the σ
/// floor and `k`, as bits.
type RunKey = (u64, u64, u64);

/// One level's reading of a [`ShapeMemo`] (see there), with the shape level
/// it reads for.
#[derive(Debug)]
pub struct ShapeReader<'m, 's> {
    shape: Shape<'s>,
    /// The kept shapes (`None` would only compute; never the case).
    shapes: Option<&'m mut Vec<(CellKey, AncestorShape)>>,
    next: usize,
}

impl ShapeMemo {
    /// The capacity of each kept run's storage (for tests of copies).
    #[cfg(test)]
    pub(crate) fn capacities(&self) -> Vec<usize> {
        self.runs
            .iter()
            .map(|(_, shapes)| shapes.capacity())
            .collect()
    }

    /// Forgets every shape, keeping the storage for the next update's
    /// (each update's shapes grew new vectors: 0.4 % of an insert's
    /// instructions, benches/SPEED_LOG.md, session 27). Runs of more than
    /// `max_runs` shape levels and options are dropped.
    pub fn clear(&mut self, max_runs: usize) {
        if self.runs.len() > max_runs {
            self.runs.clear();
        }
        for (_, shapes) in &mut self.runs {
            shapes.clear();
        }
    }

    /// A reader of the shapes of `shape`'s ancestors under σ floor
    /// `sigma_floor` and expansion `k` (the options they depend on).
    pub fn reader<'s>(
        &mut self,
        shape: Shape<'s>,
        sigma_floor: f64,
        k: f64,
    ) -> ShapeReader<'_, 's> {
        let key = (
            shape.top.cell_size().to_bits(),
            sigma_floor.to_bits(),
            k.to_bits(),
        );
        let run = match self.runs.iter().position(|(k, _)| *k == key) {
            Some(i) => self.runs.get_mut(i),
            None => {
                self.runs.push((key, Vec::new()));
                self.runs.last_mut()
            }
        };
        ShapeReader {
            shape,
            shapes: run.map(|(_, shapes)| shapes),
            next: 0,
        }
    }
}

impl<'s> ShapeReader<'_, 's> {
    /// The shape level read for.
    pub fn shape(&self) -> Shape<'s> {
        self.shape
    }

    /// The shape of the next ancestor met, `at`: the one kept when it is the
    /// next in step, else `compute`'s (kept when nothing is kept at this
    /// position yet).
    pub fn next(&mut self, at: CellKey, compute: impl FnOnce() -> AncestorShape) -> AncestorShape {
        let i = self.next;
        self.next += 1;
        let Some(shapes) = self.shapes.as_deref_mut() else {
            return compute();
        };
        match shapes.get(i) {
            Some((k, shape)) if *k == at => *shape,
            Some(_) => compute(),
            None => {
                let shape = compute();
                if i == shapes.len() {
                    shapes.push((at, shape));
                }
                shape
            }
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::pyramid::Pyramid;
    use nalgebra::{Matrix2, Vector2};
    use std::cell::Cell;

    fn shape(v: f64) -> AncestorShape {
        Some(Some(Gaussian {
            mean: Vector2::new(v, 0.0),
            inverse: Matrix2::identity() * v,
            normal: Vector2::new(0.0, 1.0),
        }))
    }

    #[test]
    fn a_memo_gives_kept_shapes_in_step_and_computes_the_rest() {
        let pyramid = Pyramid::new(0.02, 3);
        let s = pyramid.levels(0..=2).and_then(Shape::new).unwrap();
        let key = |ix| CellKey { ix, iy: 0 };
        let calls = Cell::new(0);
        let compute = |v: f64| {
            calls.set(calls.get() + 1);
            shape(v)
        };
        let mut memo = ShapeMemo::default();
        // The first level computes and keeps, in the order met.
        let mut first = memo.reader(s, 0.02, 10.0);
        assert_eq!(first.next(key(1), || compute(1.0)), shape(1.0));
        assert_eq!(first.next(key(2), || compute(2.0)), shape(2.0));
        assert_eq!(calls.get(), 2);
        // The next reads them back in step; out of step it computes (and
        // does not overwrite what is kept).
        let mut second = memo.reader(s, 0.02, 10.0);
        assert_eq!(second.next(key(1), || compute(9.0)), shape(1.0));
        assert_eq!(second.next(key(3), || compute(3.0)), shape(3.0));
        assert_eq!(calls.get(), 3);
        let mut third = memo.reader(s, 0.02, 10.0);
        assert_eq!(third.next(key(1), || compute(9.0)), shape(1.0));
        assert_eq!(third.next(key(2), || compute(9.0)), shape(2.0));
        assert_eq!(calls.get(), 3);
        // Other options are other shapes.
        let mut other = memo.reader(s, 0.02, 5.0);
        assert_eq!(other.next(key(1), || compute(5.0)), shape(5.0));
        assert_eq!(calls.get(), 4);
    }
}
