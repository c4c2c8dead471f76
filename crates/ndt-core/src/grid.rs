//! The sparse NDT grid map of §III-B: cells keyed by integer index, each
//! holding only the eq. (6) sums, never the points.

use std::sync::{Arc, Mutex, MutexGuard};

use nalgebra::{Matrix2, Vector2};

use crate::cell::CellStats;
use crate::distributions::{Changed, DistOptions, Distributions};
use crate::error::{check_finite, NdtError, Result};
use crate::key::{CellKey, KeyBounds, MAX_INDEX};
use crate::occupancy::OccupancyProbe;
use crate::pyramid::{Level, Pyramid, MAX_LEVELS};
use crate::se2::Pose2;
use crate::shape::{Shape, ShapeMemo};
use crate::spare::clone_vec;
use crate::table::CellTable;

mod deferral;
mod edit;
mod insert_many;
mod removals;

pub use edit::MAX_CELL_COUNT;
pub use removals::RemovalStamp;

/// How many prepared distribution sets (one per pyramid level and distinct
/// expansion/fusion setting) a grid keeps between calls.
const PREPARED_CAPACITY: usize = 24;

/// Smallest admissible cell size \[m\]: 1 mm, twenty times finer than the
/// paper's 2 cm and below any laser's accuracy. Finer cells only make every
/// beam walk of the §V elimination cross more cells (10⁸ for a 1 m beam on a
/// 10 nm grid: a scan would take minutes) and are most likely a unit mistake.
pub const MIN_CELL_SIZE: f64 = 1e-3;

/// Pyramid levels of a new grid: the fine cells and five coarser levels
/// (with 2 cm cells: 2, 4, 8, 16, 32 and 64 cm).
pub const DEFAULT_LEVELS: usize = 6;

/// One cell as returned to callers: index and the paper's sums in map
/// coordinates (`m = Σx`, `S = Σ x xᵀ`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellRecord {
    /// Cell index.
    pub key: CellKey,
    /// `M` of eq. (6).
    pub count: u64,
    /// `m = Σ x` in map coordinates \[m\].
    pub sum: Vector2<f64>,
    /// `S = Σ x xᵀ` in map coordinates \[m²\].
    pub scatter: Matrix2<f64>,
}

/// A scan checked by [`NdtGrid::stage`]: its points in map coordinates
/// with their finest-level cells.
#[derive(Debug, Clone, Default)]
pub(crate) struct StagedScan {
    points: Vec<(CellKey, Vector2<f64>)>,
}

/// A sparse, unbounded NDT grid map (§III-B).
///
/// Memory grows with the mapped area (occupied cells), not with the number of
/// scans. Distributions for matching are derived from the sums on demand and
/// kept up to date incrementally under [`NdtGrid::insert`].
#[derive(Debug)]
pub struct NdtGrid {
    cell_size: f64,
    inv_cell_size: f64,
    pyramid: Pyramid,
    prepared: Mutex<Vec<Arc<Distributions>>>,
    /// Fine cells changed while a deferral ([`NdtGrid::deferral`]) was open: their coarser
    /// levels and prepared distributions wait for its end (empty otherwise).
    pending: Vec<CellKey>,
    /// Open deferrals (they nest).
    deferring: u32,
    /// Who this grid is and how many fine cells it has lost
    /// ([`NdtGrid::removal_stamp`]).
    removals: removals::Removals,
    /// The ancestors' shapes of one update of the prepared distributions
    /// (emptied before each, its storage kept).
    shapes: ShapeMemo,
}

impl Clone for NdtGrid {
    /// A copy with its coarser levels up to date (a copy made inside a
    /// deferral brings its own up to date at once), its storage with the
    /// original's spare capacity (the `spare` module): inserts into the copy
    /// grow it as they would the original.
    fn clone(&self) -> Self {
        let mut copy = Self {
            cell_size: self.cell_size,
            inv_cell_size: self.inv_cell_size,
            pyramid: self.pyramid.clone(),
            // Deep copies, so that the clone's inserts update its own
            // distributions in place instead of copying them on first write.
            prepared: Mutex::new(
                self.lock_prepared()
                    .iter()
                    .map(|d| Arc::new(Distributions::clone(d)))
                    .collect(),
            ),
            pending: clone_vec(&self.pending),
            deferring: 1,
            // Another grid: its removals are its own from here on.
            removals: removals::Removals::new(),
            shapes: self.shapes.clone(),
        };
        copy.end_deferral();
        copy
    }
}

impl NdtGrid {
    /// An empty grid with square cells of `cell_size` metres (the paper: 0.02)
    /// and [`DEFAULT_LEVELS`] pyramid levels.
    pub fn new(cell_size: f64) -> Result<Self> {
        Self::with_levels(cell_size, DEFAULT_LEVELS)
    }

    /// An empty grid with `levels` pyramid levels (1 = the fine grid only, at
    /// most [`MAX_LEVELS`]); level `l` has cells of `cell_size · 2^l`.
    pub fn with_levels(cell_size: f64, levels: usize) -> Result<Self> {
        if !(cell_size.is_finite() && cell_size >= MIN_CELL_SIZE) {
            return Err(NdtError::InvalidOption {
                name: "cell_size",
                expected: "a finite cell size >= 0.001 m",
                value: cell_size,
            });
        }
        if levels == 0 || levels > MAX_LEVELS {
            return Err(NdtError::InvalidOption {
                name: "levels",
                expected: "between 1 and 12 pyramid levels",
                value: levels as f64,
            });
        }
        Ok(Self {
            cell_size,
            inv_cell_size: 1.0 / cell_size,
            pyramid: Pyramid::new(cell_size, levels),
            prepared: Mutex::new(Vec::new()),
            pending: Vec::new(),
            deferring: 0,
            removals: removals::Removals::new(),
            shapes: ShapeMemo::default(),
        })
    }

    /// Number of pyramid levels (fine level included).
    pub fn levels(&self) -> usize {
        self.pyramid.len()
    }

    /// Pyramid level `l` (0 = fine): its cell size and sums.
    pub fn level(&self, l: usize) -> Option<&Level> {
        debug_assert!(
            l == 0 || self.pending.is_empty(),
            "coarse level read in a deferral"
        );
        self.pyramid.level(l)
    }

    fn fine(&self) -> &CellTable<CellStats> {
        self.pyramid.fine().cells()
    }

    /// Cell size \[m\].
    pub fn cell_size(&self) -> f64 {
        self.cell_size
    }

    /// Number of cells holding at least one point.
    pub fn len(&self) -> usize {
        self.fine().len()
    }

    /// `true` when no point was ever inserted.
    pub fn is_empty(&self) -> bool {
        self.fine().is_empty()
    }

    /// Largest |map coordinate| a point may have \[m\].
    pub fn coordinate_limit(&self) -> f64 {
        f64::from(MAX_INDEX) * self.cell_size
    }

    /// The occupied cells as a bit mask: answers "does this cell hold points?"
    /// for runs of cells (a beam's path) without touching the sums.
    pub fn occupancy(&self) -> crate::cellmask::CellMaskReader<'_> {
        self.pyramid.occupied().cells().reader()
    }

    /// The sums of one cell about its centre, if it holds points.
    pub fn stats(&self, key: CellKey) -> Option<&CellStats> {
        self.fine().get(key)
    }

    /// Every occupied cell with its eq. (6) sums in map coordinates, sorted by
    /// key (`ix`, then `iy`) so the order is deterministic.
    pub fn cells(&self) -> Vec<CellRecord> {
        let mut out: Vec<CellRecord> = self
            .fine()
            .iter()
            .map(|(key, s)| {
                // Back from "about the centre c" to "about the origin": shift by −c.
                let abs = s.shifted(-key.center(self.cell_size));
                CellRecord {
                    key,
                    count: abs.count,
                    sum: abs.sum,
                    scatter: abs.scatter,
                }
            })
            .collect();
        out.sort_unstable_by_key(|r| r.key);
        out
    }

    /// eq. (6): adds the scan-frame `points` \[m\] seen from `pose`
    /// (`T_map_scan`) to the grid. All-or-nothing: on error (non-finite input,
    /// a point whose cell index would overflow) the grid is unchanged.
    ///
    /// Returns the keys of the cells that changed (each once, first-touch order).
    pub fn insert(&mut self, points: &[[f64; 2]], pose: Pose2) -> Result<Vec<CellKey>> {
        let staged = self.stage(points, pose, StagedScan::default())?;
        Ok(self.insert_staged(&staged))
    }

    /// The checks of [`NdtGrid::insert`], without touching the grid: the
    /// points in map coordinates with their cells, ready for
    /// [`NdtGrid::insert_staged`] (which then cannot fail).
    ///
    /// The staged points take `spare`'s storage: the odometry loop stages
    /// every scan its matching grid takes, and a new vector each time took
    /// the allocator's lock, which the mapper's helper thread may hold
    /// (benches/SPEED_LOG.md, session 27).
    pub(crate) fn stage(
        &self,
        points: &[[f64; 2]],
        pose: Pose2,
        spare: StagedScan,
    ) -> Result<StagedScan> {
        check_finite("pose", &pose.to_array())?;
        let sin_cos = pose.theta.sin_cos();
        let inv = self.inv_cell_size;
        // One pass without an exit per point (eq. 2, then the cell): whether
        // every cell exists is checked once at the end. A non-finite point
        // has no cell, so only a scan that fails is searched for one (the
        // errors of `check_values`, in its order) and then for its first
        // point beyond the lattice.
        let mut staged = spare.points;
        staged.clear();
        if crate::staging::stage_points(points, pose, sin_cos, inv, &mut staged) {
            return Ok(StagedScan { points: staged });
        }
        check_points("points", points)?;
        // Some point failed the same test, so it is found (the fallback is
        // never taken).
        let (index, w) = staged
            .iter()
            .enumerate()
            .find(|(_, (_, w))| !CellKey::of_flagged(*w, inv).1)
            .map_or((0, Vector2::zeros()), |(i, (_, w))| (i, *w));
        Err(NdtError::CellIndexOverflow {
            what: "points",
            index,
            x: w.x,
            y: w.y,
            limit: self.coordinate_limit(),
        })
    }

    /// The value checks of [`NdtGrid::stage`] (the same errors), and whether
    /// the scan surely lies within the lattice without staging it: a
    /// rotation keeps each point's distance from the scan's origin, so no
    /// point ends beyond the lattice when the farthest point's distance and
    /// the pose's translation add up to at most half of
    /// [`NdtGrid::coordinate_limit`] (a margin far above any rounding of
    /// eq. 2). `false`: only [`NdtGrid::stage`] can tell.
    pub(crate) fn check_reach(&self, points: &[[f64; 2]], pose: Pose2) -> Result<bool> {
        check_values(points, pose)?;
        let farthest = points
            .iter()
            .fold(0.0f64, |m, p| m.max(p[0] * p[0] + p[1] * p[1]))
            .sqrt();
        Ok(farthest + pose.x.hypot(pose.y) <= 0.5 * self.coordinate_limit())
    }

    /// Adds a scan staged by [`NdtGrid::stage`] on this grid: eq. (6) into
    /// every pyramid level, then the prepared distributions of the touched
    /// cells. Returns the touched finest-level keys (see [`NdtGrid::insert`]).
    pub(crate) fn insert_staged(&mut self, staged: &StagedScan) -> Vec<CellKey> {
        if self.deferring > 0 {
            let fine = self.pyramid.add_fine(&staged.points);
            self.pending.extend_from_slice(&fine);
            return fine;
        }
        let mut touched = self.pyramid.add(&staged.points);
        self.update_prepared(&touched);
        let fine = touched.first_mut().map(std::mem::take).unwrap_or_default();
        self.pyramid.give_back(touched);
        fine
    }

    /// Removes the cells `keys` (their eq. (6) sums entirely) from the grid,
    /// as the §V elimination steps delete false detections. Keys without a
    /// cell, and repeated keys, are ignored. The coarser pyramid levels lose
    /// the removed sums too, and the prepared distributions are updated
    /// exactly as [`NdtGrid::insert`] does: a removed cell loses its
    /// distribution and its minority neighbours (fused sums, §IV-A(3)) are
    /// recomputed.
    ///
    /// Returns the number of cells removed. Cannot fail.
    pub fn remove_cells(&mut self, keys: &[CellKey]) -> usize {
        if self.deferring > 0 {
            let removed = self.pyramid.remove_fine(keys);
            self.pending.extend_from_slice(&removed);
            let n = removed.len();
            self.removals.add(n);
            self.pyramid.give_back([removed]);
            return n;
        }
        let touched = self.pyramid.remove(keys);
        let removed = touched.first().map_or(0, Vec::len);
        if removed > 0 {
            self.removals.add(removed);
            self.update_prepared(&touched);
        }
        self.pyramid.give_back(touched);
        removed
    }

    /// Keys done with (e.g. those [`NdtGrid::insert`] returned, once used):
    /// the grid's next updates keep their results in that storage.
    pub(crate) fn give_back(&mut self, keys: Vec<CellKey>) {
        self.pyramid.give_back([keys]);
    }

    /// Brings the prepared distributions up to date after the pyramid
    /// changed the cells `touched` (keys per level), each touched ancestor's
    /// shape computed once for all the levels that take it.
    fn update_prepared(&mut self, touched: &[Vec<CellKey>]) {
        let prepared = self.prepared.get_mut().unwrap_or_else(|e| e.into_inner());
        let shapes = &mut self.shapes;
        shapes.clear(PREPARED_CAPACITY);
        for dist in prepared.iter_mut() {
            let l = dist.level();
            if let (Some(level), Some(keys)) = (self.pyramid.level(l), touched.get(l)) {
                let depth = dist.shape_depth();
                let shape = shape_at(&self.pyramid, l, depth);
                let changed = Changed {
                    keys,
                    indices: self.pyramid.changed_indices(l),
                    // Each level's changes list its cells' parents each
                    // once, in the order of their first changed child.
                    ancestors: shape
                        .and_then(|_| touched.get(l + depth))
                        .map_or(&[], Vec::as_slice),
                };
                Arc::make_mut(dist).update(
                    level.cells(),
                    level.cell_size(),
                    changed,
                    shape,
                    shapes,
                );
            }
        }
    }

    /// A rectangle of cell indices holding every occupied cell (possibly more:
    /// removals do not shrink it until the grid is empty); `None` for an
    /// empty grid. Walks along a beam use it to skip where no cell can be.
    pub fn key_bounds(&self) -> Option<KeyBounds> {
        self.pyramid.bounds()
    }

    /// Heap bytes the grid holds (an estimate, see
    /// [`crate::table::hash_map_bytes`]): every pyramid level's sums and the
    /// prepared distributions with their look-up tables. Divided by
    /// [`NdtGrid::len`], the memory per occupied fine cell.
    pub fn heap_bytes(&self) -> usize {
        let sums: usize = (0..self.levels())
            .filter_map(|l| self.pyramid.level(l))
            .map(|lv| lv.cells().heap_bytes())
            .sum();
        let prepared: usize = self.lock_prepared().iter().map(|d| d.heap_bytes()).sum();
        sums + self.pyramid.occupied().heap_bytes() + self.pyramid.marks_heap_bytes() + prepared
    }

    /// Keys of every occupied cell, in no particular order.
    pub fn keys(&self) -> impl Iterator<Item = CellKey> + '_ {
        self.fine().keys()
    }

    /// The distributions of pyramid level `level` for `options`, built on
    /// first use and then kept up to date by [`NdtGrid::insert`]. `None` for a
    /// level the grid does not have.
    pub(crate) fn distributions(
        &self,
        level: usize,
        options: DistOptions,
    ) -> Option<Arc<Distributions>> {
        debug_assert!(self.pending.is_empty(), "distributions read in a deferral");
        let lv = self.pyramid.level(level)?;
        let mut prepared = self.lock_prepared();
        if let Some(found) = prepared
            .iter()
            .find(|d| d.level() == level && d.options() == options)
        {
            return Some(Arc::clone(found));
        }
        let depth = shape_depth(&self.pyramid, level, options.shape_cell);
        let built = Arc::new(Distributions::build(
            lv.cells(),
            lv.cell_size(),
            level,
            options,
            shape_at(&self.pyramid, level, depth),
        ));
        if prepared.len() >= PREPARED_CAPACITY {
            prepared.remove(0);
        }
        prepared.push(Arc::clone(&built));
        Some(built)
    }

    fn lock_prepared(&self) -> MutexGuard<'_, Vec<Arc<Distributions>>> {
        // A poisoned lock only means another thread panicked while holding it;
        // the cache is rebuilt from the sums, so its content is still usable.
        self.prepared.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl NdtGrid {
    /// An [`OccupancyProbe`] of this grid: "may a cell of this block hold
    /// points?" on blocks of 32 × 32, 16 × 16, 8 × 8 and 4 × 4 fine cells,
    /// from the occupancy masks (see [`crate::occupancy`]). It read the pyramid's
    /// 32 cm and 8 cm levels before (the same blocks on a 2 cm grid, the
    /// same answers): `replay intel3k odometry 1 inline`, callgrind, in
    /// benches/SPEED_LOG.md, session 19.
    pub fn occupancy_probe(&self) -> OccupancyProbe<'_> {
        self.pyramid.occupied().probe()
    }
}

/// Levels from `level` up to the first level whose cells are at least
/// `shape_cell` \[m\] (see [`crate::shape`]); 0 when `shape_cell` is 0,
/// when `level`'s own cells are that large (only cells finer than
/// `shape_cell` take an ancestor's shape, as `MatchOptions::shape_cell`
/// says), or when no coarser level is.
fn shape_depth(pyramid: &Pyramid, level: usize, shape_cell: f64) -> usize {
    let at_least = |l: usize| {
        pyramid
            .level(l)
            .is_some_and(|lv| lv.cell_size() >= shape_cell * (1.0 - 1e-9))
    };
    if shape_cell <= 0.0 || at_least(level) {
        return 0;
    }
    (level + 1..pyramid.len())
        .find(|&l| at_least(l))
        .map_or(0, |l| l - level)
}

/// The shape level `depth` levels above `level`, if any.
fn shape_at(pyramid: &Pyramid, level: usize, depth: usize) -> Option<Shape<'_>> {
    if depth == 0 {
        return None;
    }
    pyramid.levels(level..=level + depth).and_then(Shape::new)
}

/// Rejects a non-finite pose, then non-finite points (a scan's values, as
/// [`NdtGrid::insert`] checks them).
fn check_values(points: &[[f64; 2]], pose: Pose2) -> Result<()> {
    check_finite("pose", &pose.to_array())?;
    check_points("points", points)
}

/// Rejects non-finite points.
pub(crate) fn check_points(what: &'static str, points: &[[f64; 2]]) -> Result<()> {
    match points
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        Some(index) => Err(NdtError::NonFinite {
            what,
            index,
            value: if points[index][0].is_finite() {
                points[index][1]
            } else {
                points[index][0]
            },
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Options of the default match with shape cell `shape_cell`.
    fn options(shape_cell: f64) -> DistOptions {
        DistOptions {
            expansion: 10.0,
            fuse_minority: true,
            sigma_floor: 0.02,
            shape_cell,
        }
    }

    #[test]
    fn a_clone_keeps_the_originals_storage_and_takes_an_insert_as_it_would() {
        use crate::testing::{room_map, room_scan};
        use rand::SeedableRng;
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let mut grid = room_map(&mut rng);
        // Prepared distributions of the default match, then one more insert,
        // as a loop makes them: the grid's vectors have spare capacity.
        let pose = Pose2::new(0.02, 0.01, 0.05);
        let scan = room_scan(pose, &mut rng);
        grid.match_scan(&scan, pose, &crate::MatchOptions::default())
            .unwrap();
        grid.insert(&room_scan(pose, &mut rng), pose).unwrap();
        let mut copy = grid.clone();
        // Every vector's capacity counted by `heap_bytes` is the original's
        // (a derived clone's would be its length), and the reused storage of
        // the shapes' memo too (a fresh memo's would be none).
        assert_eq!(copy.heap_bytes(), grid.heap_bytes());
        assert_eq!(copy.shapes.capacities(), grid.shapes.capacities());
        assert!(grid.shapes.capacities().iter().any(|&c| c > 0));
        // The same insert into both: the same sums and distributions.
        let pose = Pose2::new(-0.03, 0.02, -0.04);
        let scan = room_scan(pose, &mut rng);
        grid.insert(&scan, pose).unwrap();
        copy.insert(&scan, pose).unwrap();
        crate::testing::assert_same_grids(&grid, &copy);
    }

    #[test]
    fn only_cells_finer_than_the_shape_cell_take_an_ancestors_shape() {
        let mut grid = NdtGrid::new(0.02).unwrap();
        // Two walls, and three lone points: cells of fewer than 3 points
        // (fused, §IV-A(3)) under ancestors without a shape.
        let mut points: Vec<[f64; 2]> = (0..200)
            .map(|i| [-1.5 + 0.015 * f64::from(i), 0.4 + 0.002 * f64::from(i)])
            .collect();
        points.extend((0..120).map(|i| [1.2, -1.0 + 0.017 * f64::from(i)]));
        points.extend([[-2.0, -2.0], [2.5, 1.9], [0.0, -2.4]]);
        grid.insert(&points, Pose2::new(0.1, -0.2, 0.3)).unwrap();
        // 2, 4, 8 and 16 cm take the 32 cm ancestors' shapes; 32 and 64 cm
        // cells are not finer than 32 cm and keep their own.
        let depths: Vec<usize> = (0..grid.levels())
            .map(|l| grid.distributions(l, options(0.32)).unwrap().shape_depth())
            .collect();
        assert_eq!(depths, [4, 3, 2, 1, 0, 0]);
        // With a 30 cm shape cell the 16 cm level still takes the 32 cm one's.
        let depths: Vec<usize> = (0..grid.levels())
            .map(|l| grid.distributions(l, options(0.3)).unwrap().shape_depth())
            .collect();
        assert_eq!(depths, [4, 3, 2, 1, 0, 0]);
        // The 32 cm level's distributions are the paper's (shapes off), bit
        // for bit, for every cell.
        let level = grid.level(4).unwrap();
        let own = Distributions::build(level.cells(), level.cell_size(), 4, options(0.0), None);
        let kept = grid.distributions(4, options(0.32)).unwrap();
        assert!(!own.is_empty());
        assert_eq!(kept.len(), own.len());
        for (key, _) in level.cells().iter() {
            assert_eq!(kept.get(key), own.get(key), "{key:?}");
        }
    }
}
