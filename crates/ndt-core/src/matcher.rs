//! NDT scan matching against an [`NdtGrid`] (§III-A with the fixes of §IV-A).

use std::borrow::Borrow;
use std::sync::Arc;

use nalgebra::{Matrix3, Vector2};

use crate::batch::{PairBlock, PassTerms, Scan};
use crate::cell::DEFAULT_SIGMA_FLOOR;
use crate::degeneracy::{constrained_projector, unconstrained_directions};
use crate::distributions::{CursorVisitor, DistLookup, DistOptions, Distributions};
use crate::error::{check_bound, check_finite, NdtError, Result};
use crate::grid::{check_points, NdtGrid};
use crate::information::{own_cell_pairs, point_to_plane_information};
use crate::key::CellKey;
use crate::memo::LevelMemo;
use crate::neighbor::nearest_in_rings_with;
use crate::pairs::{chunk_weights, evaluate_streaming, ScanPairs};
use crate::quadratic::QuadraticModel;
use crate::reduce::voxel_runs;
use crate::score::{Order, ScoreTerms};
use crate::se2::Pose2;
use crate::solver::{covariance_from_hessian, minimise, SolverOptions};

/// Largest admissible neighbour-search radius \[cells\].
pub const MAX_SEARCH_RADIUS: u32 = 1000;

/// Pyramid levels summed in one coarse-to-fine stage: the stage's own level
/// and the next coarser one. The coarser level keeps the wall-scale structure
/// that sparse fine cells lack. Measured on 24 real scan pairs (Intel, ACES,
/// FR079, MIT CSAIL; 6 local and 6 wide starts each; 5 levels, 3×3 pairing):
/// success 62 % / 59 % (local / wide) with the stage's level alone, 82 % / 77 %
/// with a window of 2, 78 % / 73 % with 3.
pub const LEVEL_WINDOW: usize = 2;

/// Default [`MatchOptions::shape_cell`] \[m\]: fine cells take the covariance
/// of the 32 cm cell they lie in (16 × 16 fine cells of 2 cm). Measured with
/// the default match on the SICK pairs of `benches/convergence.py` (success,
/// local / wide starts; benchmark pairs | held-out pairs): off 81.5 / 79.6 |
/// 75.3 / 73.9 %, 16 cm 80.8 / 79.1 | 77.9 / 76.4 %, 32 cm 80.8 / 78.9 |
/// 79.3 / 77.5 %, 64 cm 75.8 / 74.5 | 77.2 / 75.1 %; then checked on two
/// further sets chosen afterwards (`--offset 0.25`, `0.75`): off 75.7 / 73.9
/// and 76.7 / 74.3 %, 32 cm 76.4 / 74.9 and 79.5 / 78.3 %.
pub const DEFAULT_SHAPE_CELL: f64 = 0.32;

/// Largest coarsest-level cell \[m\] of the automatic level count: the coarse
/// stage must still see a room's walls as separate structures. Stopping at
/// 32 cm instead (`benches/skip_levels.py`, session 18) matched as well from
/// starts within ±0.4 m and ±10° and 6 % faster, but lost 38 / 52 / 132 of
/// 3840 real SICK starts from ±0.6 / 0.8 / 1.2 m: the 64 cm level widens
/// the basin.
pub const AUTO_COARSEST_CELL: f64 = 0.64;

/// The most pyramid levels, at least 1 and at most `available`, whose
/// coarsest cell is at most `coarsest` \[m\] on a grid of `cell_size` m
/// cells (level `l` has cells `2^l` times the fine size).
pub fn levels_up_to(cell_size: f64, coarsest: f64, available: usize) -> usize {
    (1..=available)
        .take_while(|&l| cell_size * f64::from(1u32 << (l - 1)) <= coarsest * 1.0001)
        .last()
        .unwrap_or(1)
}

/// Voxel side, as a fraction of the coarsest level's cell, on which the
/// rotated starts of the rotational multi-start are first solved
/// ([`crate::reduce::voxel_runs`]). Measured with `benches/convergence.py`'s
/// 960 real SICK pairs split in two halves of 480 (success from local / wide
/// starts, out of 3840 each): every point 3016 / 2979 and 3128 / 3067;
/// 0.25: 2997 / 2952 and 3134 / 3060; 0.5: 3024 / 2982 and 3136 / 3062;
/// 1.0: 3019 / 2959 and 3138 / 3053. 0.5 took the criterion 683-point 2 cm
/// match from 790 to 642 µs.
pub const CANDIDATE_VOXEL: f64 = 0.5;

/// The default [`MatchOptions::rotation_gate`].
pub const DEFAULT_ROTATION_GATE: f64 = 0.9;

/// Options of [`NdtGrid::match_scan`]. The defaults are the paper's method
/// (§IV-A: `k = 10`, neighbour search and fusion on) run coarse to fine over
/// the pyramid (2–64 cm on a 2 cm grid) with a ±0.15 rad rotational
/// multi-start on the coarsest level, unconstrained directions frozen, a 2 cm
/// σ floor and fine cells shaped by their 32 cm ancestor — the best of the
/// settings measured by `benches/convergence.py` (see
/// BENCHMARK.md). Neighbour search looks 1 cell around an empty cell (larger
/// radii measured worse: points get paired with the wrong wall). The paper's
/// method alone is `levels = Some(1), rotation_search = 0,
/// freeze_unconstrained = false, search_radius = 3, sigma_floor = 0.005,
/// shape_cell = 0`; the original NDT of Biber
/// & Strasser on the same grid is additionally `expansion = 1`,
/// `neighbor_search = false`, `fuse_minority = false`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MatchOptions {
    /// `k` of eq. (8) (> 0; 1 = no expansion).
    pub expansion: f64,
    /// Smallest standard deviation \[m\] a cell's distribution is given before
    /// the expansion (> 0): the scatter between two scans of one surface
    /// (range noise, beam footprint, sampling). Default
    /// [`DEFAULT_SIGMA_FLOOR`] (2 cm), chosen by measurement (see there);
    /// lower it for a more precise sensor.
    pub sigma_floor: f64,
    /// Cells finer than this \[m\] take the covariance shape of their ancestor
    /// of at least this size, around their own mean ([`crate::shape`]): the
    /// wall segment they lie on, so fine cells constrain a scan across a
    /// surface, not along it. 0 = off (the paper's distributions). Default
    /// [`DEFAULT_SHAPE_CELL`].
    pub shape_cell: f64,
    /// §IV-A(1): pair points whose own cell has no distribution with a nearby
    /// cell's (see [`crate::neighbor::nearest_in_rings`]).
    pub neighbor_search: bool,
    /// Neighbour-search radius \[cells\] (Chebyshev distance), ≤ [`MAX_SEARCH_RADIUS`].
    pub search_radius: u32,
    /// §IV-A(3): fuse cells with fewer than 3 points with their neighbours.
    pub fuse_minority: bool,
    /// Score each point against every distribution of the 3×3 block of cells
    /// around it (summed, as Biber's overlapping grids and Magnusson's NDT do)
    /// instead of its own cell's alone; points with none there fall back to
    /// the neighbour search. Smooths the score of fine cells.
    pub pair_neighbors: bool,
    /// Newton iterations at most.
    pub max_iterations: u32,
    /// Convergence threshold on the translation step \[m\].
    pub translation_tolerance: f64,
    /// Convergence threshold on the rotation step \[rad\].
    pub rotation_tolerance: f64,
    /// Largest translation per Newton step \[cells\]. With 2 cm cells a long
    /// step jumps past the narrow basin (§IV-A); 2 cells keeps it inside.
    pub max_step_cells: f64,
    /// Largest rotation per Newton step \[rad\].
    pub max_step_rotation: f64,
    /// Half-width \[rad\] of the rotational multi-start of the first stage: it
    /// also solves from the guess turned by ± this angle and keeps the best
    /// score (0 = off). Measured on real pairs with ±10° starts: 65 % success
    /// without, 70 % with 0.15 rad. Above the fine level the turned starts
    /// are first solved on run centroids (see [`CANDIDATE_VOXEL`]).
    pub rotation_search: f64,
    /// In a match over several levels, the rotational multi-start runs only
    /// when the first stage's solve from the guess ends with a score of
    /// eq. (1) per scan point below this. (With one level the first stage is
    /// the last: a turned start that lands higher is a better result within
    /// the basin too, so it always runs. Over the pyramid the later stages
    /// refine whatever basin the first one chose.)
    /// A point's term is at most 1 (on its distribution's mean), and a scan
    /// sampled from the distributions it is paired with scores about
    /// `k / (k + 1)` per point (0.91 with `k = 10`): a first stage at 0.9
    /// has nearly every point where a distribution expects it, so it is not
    /// in a wrong rotational basin, and a turned start could only add a few
    /// points. `inf` = always (the method before this gate); 0 = never.
    /// Measured with the success sets of `benches/sigma_floor.py`'s pairs
    /// (`benches/rotation_gate.py`, benches/SPEED_LOG.md, session 9): at 0.9, 6182 /
    /// 6052 successes of 7680 local / wide starts on real SICK pairs against
    /// 6189 / 6054 always, the same on held-out SICK, URG-04LX and
    /// simulated pairs; the median match of real URG-04LX scans of at least
    /// 500 points 0.18–0.22 against 0.21–0.27 ms (three runs).
    pub rotation_gate: f64,
    /// Keep the pose where the previous stage put it along directions the
    /// scan does not constrain (a corridor's axis), instead of letting fine
    /// cells drag it along: from the second stage on, Newton steps are
    /// projected onto the constrained directions of the point-to-plane
    /// information (see [`crate::degeneracy::constrained_projector`]).
    pub freeze_unconstrained: bool,
    /// With `freeze_unconstrained`: a direction is frozen when its curvature
    /// is below this fraction of the strongest (in \[0, 1\]; default
    /// [`crate::degeneracy::FREEZE_RATIO`]).
    pub freeze_ratio: f64,
    /// Pyramid levels to match on, coarse to fine (1 = the fine grid only,
    /// the paper's method). Level `l` has cells `2^l` times the fine size.
    /// Stage `l` (from `levels − 1` down to 0) starts from the previous
    /// stage's pose and minimises `−(E_l + E_{l+1})`: its level's score plus
    /// the next coarser one's (see [`LEVEL_WINDOW`]; the coarser one as its
    /// quadratic model with [`MatchOptions::coarse_model`]), so the final
    /// stage includes the fine cells. `None`: as many of the grid's levels as keep
    /// the coarsest cell at most [`AUTO_COARSEST_CELL`] (with 2 cm cells: 6
    /// levels, 2–64 cm; with 20 cm cells: 2 levels).
    pub levels: Option<u32>,
    /// Pyramid levels the coarse-to-fine stages pass over, as a mask (bit `l`
    /// for level `l`): a skipped level is neither matched on nor prepared, and
    /// the stage below it takes the next matched coarser level as its window's
    /// coarser one. The fine level (bit 0) cannot be skipped; the coarsest
    /// matched level is matched whatever its bit says (it depends on
    /// [`MatchOptions::levels`]). 0: every level. Default
    /// [`DEFAULT_SKIP_LEVELS`] (level 1, 4 cm on a 2 cm grid).
    pub skip_levels: u32,
    /// From the second coarse-to-fine stage on, score the coarser level of
    /// the stage's window by its second-order expansion about the stage's
    /// start ([`crate::quadratic`]) instead of every point at every trial
    /// pose; the final pose's score and Hessian are then computed exactly.
    /// About 40 % fewer passes over the scan. Measured with
    /// `benches/convergence.py` (8 × 960 real SICK pairs, 8 starts each):
    /// 6189 / 6054 successes from local / wide starts against 6204 / 6063
    /// with every level scored exactly (`false`), median time 0.22 / 0.27
    /// against 0.31 / 0.38 ms; `false` is the method before the model.
    pub coarse_model: bool,
    /// Score scans of at least [`PARALLEL_MIN_POINTS`] points on all cores
    /// (rayon's global pool: `RAYON_NUM_THREADS` limits it), in fixed chunks
    /// of [`PARALLEL_CHUNK`] points summed in order, so the result does not
    /// depend on the number of threads; it differs from the one-thread sum in
    /// the last bits. The match runs on a thread of the pool, and each chunk
    /// streams its points as one thread streams a large scan. Off by default,
    /// as Python threads matching different scans, and `match_many`, use the
    /// cores with less hand-over (the GIL is released while matching). On 2
    /// cores (`cargo bench --bench core -- match_large`, synthetic room, 2
    /// cm, three runs in turn with the build before, session 53): 2048 /
    /// 4096 / 8192 / 16384 / 32000 points matched 1.31–1.39 / 1.41–1.48 /
    /// 1.76–1.85 / 1.69–1.84 / 1.65–1.79× faster than on one thread, where
    /// the build before (from 16384 points, in chunks of 2048 points keeping
    /// their pairs, the pool woken for each evaluation) gave 0.81–0.92 /
    /// 0.70–0.80× at 16384 / 32000 points in the same runs (1.20 / 1.36× in
    /// session 52's `cargo bench`). The pool starts with the first such match
    /// and keeps the CPU affinity of the thread that made it (one thread per
    /// CPU that thread may run on): made from a thread pinned to one CPU, it
    /// has one thread, on that CPU.
    pub parallel: bool,
}

/// The default [`MatchOptions::skip_levels`]: level 1 (4 cm cells on a 2 cm
/// grid), as the odometry loop has skipped it since session 17
/// ([`crate::odometry::ODOMETRY_SKIP_LEVELS`]). Scan-to-scan matches of the
/// success sets of `benches/sigma_floor.py` (`benches/skip_levels.py`, 8
/// starts per pair, local / wide): real SICK pairs 6173 / 6050 of 7680
/// against 6182 / 6052 on every level, held-out SICK 6151 / 6064 against
/// 6139 / 6060, URG-04LX 109 / 107 and simulated 128 / 126 both ways, and
/// from wider starts (±0.6 to ±1.2 m, ±15 to ±30°) 2918 / 2640 / 1946 of
/// 3840 SICK starts against 2917 / 2635 / 1943; the median match of URG-04LX
/// scans of at least 500 points 16–27 % faster in three runs (0.141 against
/// 0.187 ms in the last), and the distributions an insert keeps up to date
/// one level fewer (`insert_loop`: 1.04 → 0.89 M instructions per 683-point
/// insert). benches/SPEED_LOG.md, session 18.
pub const DEFAULT_SKIP_LEVELS: u32 = 1 << 1;

/// Smallest scan [`MatchOptions::parallel`] splits: 1024 points gained
/// nothing on 2 cores (`large_probe`, 0.094–0.102 against 0.095–0.146 ms),
/// 2048 points 1.3–1.4× (session 53).
pub const PARALLEL_MIN_POINTS: usize = 2048;

/// Points per chunk of a parallel evaluation: small enough that 2 threads
/// share a scan of a few chunks evenly (chunks of 2048 points left 6144
/// points slower on 2 threads than on one, 0.78–0.80 against 0.63–0.65 ms;
/// 512: 0.37–0.38 ms), large enough that each is worth a task (256 points
/// were 6 % slower at 32000 points). `large_probe`, session 53.
pub const PARALLEL_CHUNK: usize = 512;

impl Default for MatchOptions {
    fn default() -> Self {
        Self {
            expansion: 10.0,
            sigma_floor: DEFAULT_SIGMA_FLOOR,
            shape_cell: DEFAULT_SHAPE_CELL,
            neighbor_search: true,
            search_radius: 1,
            fuse_minority: true,
            pair_neighbors: false,
            max_iterations: 50,
            translation_tolerance: 1e-4,
            rotation_tolerance: 1e-4,
            max_step_cells: 2.0,
            max_step_rotation: 0.05,
            rotation_search: 0.15,
            rotation_gate: DEFAULT_ROTATION_GATE,
            freeze_unconstrained: true,
            freeze_ratio: crate::degeneracy::FREEZE_RATIO,
            levels: None,
            skip_levels: DEFAULT_SKIP_LEVELS,
            coarse_model: true,
            parallel: false,
        }
    }
}

impl MatchOptions {
    /// The paper's method alone (§III-A with the fixes of §IV-A): the fine
    /// grid only, `k = 10`, neighbour search (3 cells) and minority fusion;
    /// no pyramid, rotational multi-start or frozen directions; each cell's
    /// own covariance (eq. 7) regularised to a 5 mm σ (the paper states none).
    /// Python: `ndtgrid.presets.PAPER`.
    pub fn paper() -> Self {
        Self {
            levels: Some(1),
            rotation_search: 0.0,
            freeze_unconstrained: false,
            search_radius: 3,
            sigma_floor: 0.005,
            shape_cell: 0.0,
            ..Self::default()
        }
    }

    /// Biber & Strasser's original NDT on the same grid: [`MatchOptions::paper`]
    /// with `k = 1`, no neighbour search and no fusion. Python:
    /// `ndtgrid.presets.ORIGINAL_NDT`.
    pub fn original_ndt() -> Self {
        Self {
            expansion: 1.0,
            neighbor_search: false,
            fuse_minority: false,
            ..Self::paper()
        }
    }

    /// Checks every option's range.
    pub fn validate(&self) -> Result<()> {
        let positive = |name: &'static str, value: f64| {
            check_bound(name, "a finite value > 0", value, 0.0, true)
        };
        positive("expansion", self.expansion)?;
        positive("sigma_floor", self.sigma_floor)?;
        if !(self.freeze_ratio.is_finite() && (0.0..=1.0).contains(&self.freeze_ratio)) {
            return Err(NdtError::InvalidOption {
                name: "freeze_ratio",
                expected: "a ratio in [0, 1]",
                value: self.freeze_ratio,
            });
        }
        check_bound(
            "shape_cell",
            "a finite size >= 0 m",
            self.shape_cell,
            0.0,
            false,
        )?;
        positive("translation_tolerance", self.translation_tolerance)?;
        positive("rotation_tolerance", self.rotation_tolerance)?;
        positive("max_step_cells", self.max_step_cells)?;
        positive("max_step_rotation", self.max_step_rotation)?;
        if !(self.rotation_search.is_finite()
            && (0.0..=std::f64::consts::PI).contains(&self.rotation_search))
        {
            return Err(NdtError::InvalidOption {
                name: "rotation_search",
                expected: "an angle in [0, pi] rad",
                value: self.rotation_search,
            });
        }
        if self.rotation_gate.is_nan() || self.rotation_gate < 0.0 {
            return Err(NdtError::InvalidOption {
                name: "rotation_gate",
                expected: "a score per point >= 0 (inf = the multi-start always)",
                value: self.rotation_gate,
            });
        }
        if self.skip_levels & 1 != 0 || self.skip_levels >> crate::pyramid::MAX_LEVELS != 0 {
            return Err(NdtError::InvalidOption {
                name: "skip_levels",
                expected: "a mask of pyramid levels 1 to 11 (the fine level cannot be skipped)",
                value: f64::from(self.skip_levels),
            });
        }
        if self.search_radius > MAX_SEARCH_RADIUS {
            return Err(NdtError::InvalidOption {
                name: "search_radius",
                expected: "a radius of at most 1000 cells",
                value: f64::from(self.search_radius),
            });
        }
        Ok(())
    }

    /// Solver settings on pyramid level `level` with cells of `cell_size` m:
    /// coarse levels only need to land inside the next level's basin, so their
    /// tolerances grow with the cell (× 2^level).
    fn solver_options(&self, cell_size: f64, level: usize) -> SolverOptions {
        let scale = f64::from(1u32 << level.min(30));
        SolverOptions {
            max_iterations: self.max_iterations,
            translation_tolerance: self.translation_tolerance * scale,
            rotation_tolerance: self.rotation_tolerance * scale,
            max_step_translation: self.max_step_cells * cell_size,
            max_step_rotation: self.max_step_rotation,
            projector: Matrix3::identity(),
        }
    }

    /// Whether a scan of `points` points is scored on all cores
    /// ([`MatchOptions::parallel`] and at least [`PARALLEL_MIN_POINTS`]).
    fn splits(&self, points: usize) -> bool {
        self.parallel && points >= PARALLEL_MIN_POINTS
    }

    fn dist_options(&self) -> DistOptions {
        DistOptions {
            expansion: self.expansion,
            sigma_floor: self.sigma_floor,
            shape_cell: self.shape_cell,
            fuse_minority: self.fuse_minority,
        }
    }
}

/// The outcome of one match.
#[derive(Debug, Clone, PartialEq)]
pub struct MatchResult {
    /// Best pose `T_map_scan` found.
    pub pose: Pose2,
    /// The solver met its step tolerance (not merely ran out of iterations).
    pub converged: bool,
    /// Newton steps taken.
    pub iterations: u32,
    /// `E(p)` of eq. (1) at `pose`, with the distributions used.
    pub score: f64,
    /// Points that had a reference distribution at `pose`.
    pub num_matched: usize,
    /// Hessian of `−E` at `pose` (order `tx, ty, θ`).
    pub hessian: Matrix3<f64>,
    /// Pose covariance estimate, see [`covariance_from_hessian`].
    pub covariance: Matrix3<f64>,
    /// Pose directions the scan does not constrain, as `(dx, dy, dθ)`: those
    /// of [`unconstrained_directions`] for the point-to-plane information of
    /// the points paired on the coarsest level of the final stage (see
    /// [`crate::information`]); empty when every direction is constrained.
    pub unconstrained: Vec<[f64; 3]>,
}

/// Most points whose pairs a match keeps on one thread (about 100 bytes a
/// point and level, [`crate::pairs`]): beyond, each evaluation streams the
/// points through a small block ([`evaluate_streaming`], the same terms),
/// whose look-ups cost less than reading kept pairs that no longer fit in
/// the caches. `cargo bench --bench core -- match_large/one_thread`,
/// alternating with the build before kept pairs (595ccaa), three rounds
/// each: with every scan's pairs kept, 8192 points took 1.95 ms against
/// 1.67–2.17 ms, 16384 points 4.30–4.46 against 3.49–3.74 ms and 32000
/// points 9.2–11.4 against 7.8–8.3 ms; streamed beyond 4096 points, 8192
/// points 2.09–2.16 against 2.03–2.21 ms and 32000 points 7.9–8.7 against
/// 7.6–8.5 ms, while 2000 points (kept) take 338–359 against 457–563 µs.
pub const KEPT_MAX_POINTS: usize = 4096;

/// Levels whose pairs a match keeps at once ([`MatchPairs`]): a stage
/// scores its own level and, at its start and for the final pose, the next
/// coarser one.
const KEPT_LEVELS: usize = 2;

/// The pairs of one set of (weighted) points kept during one match, for the
/// last [`KEPT_LEVELS`] levels evaluated ([`crate::pairs`]): so that each
/// evaluation looks up only the points that changed cell. A scan of more
/// than [`KEPT_MAX_POINTS`] points, or one that [`MatchOptions::parallel`]
/// splits, keeps none: each evaluation streams its points, split into
/// chunks of [`PARALLEL_CHUNK`] points on all cores and summed in order
/// when parallel ([`evaluate_chunks`]).
struct MatchPairs<'a> {
    points: &'a [[f64; 2]],
    weights: Option<&'a [f64]>,
    parallel: bool,
    /// Pairs are kept (else every evaluation streams the points through a
    /// small block, [`evaluate_streaming`]).
    keep: bool,
    kept: Vec<(usize, ScanPairs<'a>)>,
}

impl<'a> MatchPairs<'a> {
    fn new(points: &'a [[f64; 2]], weights: Option<&'a [f64]>, options: &MatchOptions) -> Self {
        let parallel = options.splits(points.len());
        Self {
            points,
            weights,
            parallel,
            keep: !parallel && points.len() <= KEPT_MAX_POINTS,
            kept: Vec::with_capacity(KEPT_LEVELS),
        }
    }

    /// For a single evaluation: nothing kept (no storage for the whole
    /// scan), the same terms.
    fn once(points: &'a [[f64; 2]], options: &MatchOptions) -> Self {
        Self {
            keep: false,
            ..Self::new(points, None, options)
        }
    }

    /// The kept pairs of `level`: those kept, else the coarsest level's
    /// (coarse to fine, it is done with), else new ones.
    fn level(&mut self, level: usize) -> &mut ScanPairs<'a> {
        let at = match self.kept.iter().position(|(l, _)| *l == level) {
            Some(at) => at,
            None if self.kept.len() >= KEPT_LEVELS => {
                let coarsest = (self.kept.iter().enumerate())
                    .max_by_key(|(_, (l, _))| *l)
                    .map_or(0, |(i, _)| i);
                if let Some(k) = self.kept.get_mut(coarsest) {
                    k.0 = level;
                }
                coarsest
            }
            None => {
                let pairs = ScanPairs::new(self.points, self.weights);
                self.kept.push((level, pairs));
                self.kept.len() - 1
            }
        };
        let len = self.kept.len();
        &mut self.kept[at.min(len - 1)].1
    }

    /// Score terms of the points at `pose` on `dists`' level (see
    /// [`crate::pairs::ScanPairs::evaluate`]; with
    /// [`MatchOptions::pair_neighbors`], [`evaluate_block`]).
    fn evaluate(
        &mut self,
        dists: &Distributions,
        pose: Pose2,
        options: &MatchOptions,
        order: Order,
    ) -> PassTerms {
        let inv_cell = 1.0 / dists.cell_size();
        if options.pair_neighbors {
            return evaluate_block(
                dists,
                self.points,
                self.weights,
                pose,
                inv_cell,
                options,
                order,
            );
        }
        let radius = options.neighbor_search.then_some(options.search_radius);
        if self.keep {
            let pairs = self.level(dists.level());
            return pairs.evaluate(dists, pose, inv_cell, radius, order);
        }
        let (points, weights) = (self.points, self.weights);
        if !self.parallel {
            return evaluate_streaming(dists, points, weights, pose, inv_cell, radius, order);
        }
        evaluate_chunks(points, weights, |chunk, w| {
            evaluate_streaming(dists, chunk, w, pose, inv_cell, radius, order)
        })
    }
}

/// The terms of a large scan's chunks of [`PARALLEL_CHUNK`] points
/// (`chunk_terms` of each chunk's points and weights), on all cores, summed
/// in order: the same bits whatever the number of threads. Streamed, as one
/// thread streams a scan of more than [`KEPT_MAX_POINTS`] points: with each
/// chunk's pairs kept instead, all chunks together no longer fit in the
/// caches (`large_probe`, 32000 points, `RAYON_NUM_THREADS=1`, the pairs kept
/// in chunks of 2048 points: 6.5–6.9 ms, against 4.3 ms streamed on one
/// thread; benches/SPEED_LOG.md, session 53).
fn evaluate_chunks<F>(points: &[[f64; 2]], weights: Option<&[f64]>, chunk_terms: F) -> PassTerms
where
    F: Fn(&[[f64; 2]], Option<&[f64]>) -> PassTerms + Sync,
{
    use rayon::prelude::*;
    let parts: Vec<PassTerms> = points
        .par_chunks(PARALLEL_CHUNK)
        .enumerate()
        .map(|(i, chunk)| {
            chunk_terms(
                chunk,
                chunk_weights(weights, i, PARALLEL_CHUNK, chunk.len()),
            )
        })
        .collect();
    sum_parts(&parts)
}

/// `work` on a thread of rayon's pool when `split` (a match that scores its
/// scan on all cores) and the caller is not one already, else on the
/// calling thread ([`NdtGrid::match_checked`] says why).
fn on_pool<R: Send>(split: bool, work: impl FnOnce() -> R + Send) -> R {
    if split && rayon::current_thread_index().is_none() {
        rayon::scope(|_| work())
    } else {
        work()
    }
}

/// The terms of disjoint parts of a scan, summed in order.
fn sum_parts(parts: &[PassTerms]) -> PassTerms {
    let mut total = PassTerms {
        terms: ScoreTerms::default(),
        information: Matrix3::zeros(),
    };
    for t in parts {
        total.terms.add_terms(&t.terms);
        total.terms.matched += t.terms.matched; // disjoint points
        total.information += t.information;
    }
    total
}

/// Score terms of the whole scan at `pose` with every point scored against
/// the 3×3 block of cells around it ([`MatchOptions::pair_neighbors`]):
/// with [`MatchOptions::parallel`] and a large scan, chunk by chunk on all
/// cores (see there).
fn evaluate_block(
    dists: &Distributions,
    points: &[[f64; 2]],
    weights: Option<&[f64]>,
    pose: Pose2,
    inv_cell: f64,
    options: &MatchOptions,
    order: Order,
) -> PassTerms {
    if !options.splits(points.len()) {
        return evaluate_block_serial(dists, points, weights, pose, inv_cell, options, order);
    }
    evaluate_chunks(points, weights, |chunk, w| {
        evaluate_block_serial(dists, chunk, w, pose, inv_cell, options, order)
    })
}

/// [`evaluate_block`] on one thread.
fn evaluate_block_serial(
    dists: &Distributions,
    points: &[[f64; 2]],
    weights: Option<&[f64]>,
    pose: Pose2,
    inv_cell: f64,
    options: &MatchOptions,
    order: Order,
) -> PassTerms {
    dists.visit(Evaluation {
        points,
        weights,
        pose,
        inv_cell,
        options,
        order,
    })
}

/// The arguments of [`evaluate_block_serial`], run with the distributions'
/// reader of whichever kind (see [`Distributions::visit`]).
struct Evaluation<'a> {
    points: &'a [[f64; 2]],
    weights: Option<&'a [f64]>,
    pose: Pose2,
    inv_cell: f64,
    options: &'a MatchOptions,
    order: Order,
}

impl CursorVisitor for Evaluation<'_> {
    type Out = PassTerms;

    fn visit<L: DistLookup>(self, mut cursor: L) -> PassTerms {
        let (pose, inv_cell, options, weights) =
            (self.pose, self.inv_cell, self.options, self.weights);
        let scan = Scan::new(pose, self.order);
        let mut matched = 0;
        let mut block = PairBlock::default();
        for (i, p) in self.points.iter().enumerate() {
            let w = weights.and_then(|w| w.get(i)).copied().unwrap_or(1.0);
            let xw = pose.transform_with(scan.sin_cos, Vector2::new(p[0], p[1]));
            let Some(key) = CellKey::of(xw, inv_cell) else {
                continue;
            };
            let mut any = false;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(g) = cursor.get(key.offset(dx, dy)) {
                        block.push(*p, w, g.borrow(), dx == 0 && dy == 0, &scan);
                        any = true;
                    }
                }
            }
            if any {
                matched += 1;
                continue;
            }
            if options.neighbor_search {
                if let Some(g) = nearest_in_rings_with(&mut cursor, xw, key, options.search_radius)
                {
                    block.push(*p, w, g.borrow(), false, &scan);
                    matched += 1;
                }
            }
        }
        block.finish(&scan, matched)
    }
}

/// Score terms of (weighted) points (those of `pairs`) at `pose` summed
/// over the pyramid levels of one coarse-to-fine stage (see
/// [`LEVEL_WINDOW`]); with a `memo`, each level's terms are taken from it
/// when computed there before, and recorded.
fn stack_terms(
    stack: &[(usize, Arc<Distributions>)],
    pairs: &mut MatchPairs<'_>,
    pose: Pose2,
    options: &MatchOptions,
    order: Order,
    mut memo: Option<&mut LevelMemo>,
) -> ScoreTerms {
    let mut total = ScoreTerms::default();
    for (level, d) in stack {
        let known = memo.as_ref().and_then(|m| m.get(*level, pose, order));
        let t = known.unwrap_or_else(|| pairs.evaluate(d, pose, options, order));
        if known.is_none() {
            if let Some(m) = memo.as_mut() {
                m.put(*level, pose, order, t);
            }
        }
        total.add_terms(&t.terms);
        // The same points on each level.
        total.matched = total.matched.max(t.terms.matched);
    }
    total
}

/// The error of an empty `expansion_phases`.
const NO_PHASES: NdtError = NdtError::InvalidOption {
    name: "expansion_phases",
    expected: "at least one expansion",
    value: 0.0,
};

/// Rejects phases [`NdtGrid::match_phased`] cannot solve with: none, or an
/// expansion `options` cannot take.
pub(crate) fn check_phases(options: &MatchOptions, phases: &[f64]) -> Result<()> {
    if phases.is_empty() {
        return Err(NO_PHASES);
    }
    phases.iter().try_for_each(|&expansion| {
        MatchOptions {
            expansion,
            ..*options
        }
        .validate()
    })
}

/// The score terms with derivatives of every level of `stack` at `pose`
/// (from the memo where computed there before).
fn exact_terms(
    stack: &[(usize, Arc<Distributions>)],
    pairs: &mut MatchPairs<'_>,
    pose: Pose2,
    options: &MatchOptions,
    memo: &mut LevelMemo,
) -> ScoreTerms {
    stack_terms(stack, pairs, pose, options, Order::Derivatives, Some(memo))
}

impl NdtGrid {
    /// Matches scan-frame `points` \[m\] against the grid from `guess`
    /// (`T_map_scan`) by Newton's method on eq. (1).
    ///
    /// Errors on empty or non-finite input, on points beyond
    /// [`NdtGrid::coordinate_limit`], and on invalid options; never on a
    /// failed solve (see [`MatchResult::converged`]).
    pub fn match_scan(
        &self,
        points: &[[f64; 2]],
        guess: Pose2,
        options: &MatchOptions,
    ) -> Result<MatchResult> {
        options.validate()?;
        self.check_scan(points, guess)?;
        let levels = self.match_levels(options)?;
        self.match_checked(points, guess, options, levels)
    }

    /// [`NdtGrid::match_scan`] once its input is checked (`options` valid,
    /// [`NdtGrid::check_scan`] passed) on `levels` levels
    /// ([`NdtGrid::match_levels`]).
    ///
    /// A match that scores its scan on all cores ([`MatchOptions::parallel`])
    /// runs on a thread of rayon's pool from start to end, which takes the
    /// chunks of each evaluation with the pool's other threads: a thread
    /// outside the pool would hand every evaluation to the pool and sleep
    /// until it is done, a wake-up each way per evaluation, about 12 a
    /// match (`large_probe`, 32000 points in chunks of 2048: 2.4–2.5 ms
    /// against 2.6–3.1 ms; benches/SPEED_LOG.md, session 53).
    pub(crate) fn match_checked(
        &self,
        points: &[[f64; 2]],
        guess: Pose2,
        options: &MatchOptions,
        levels: usize,
    ) -> Result<MatchResult> {
        on_pool(options.splits(points.len()), || {
            self.coarse_to_fine(points, guess, options, levels)
        })
    }

    /// [`NdtGrid::match_checked`] on the calling thread.
    fn coarse_to_fine(
        &self,
        points: &[[f64; 2]],
        guess: Pose2,
        options: &MatchOptions,
        levels: usize,
    ) -> Result<MatchResult> {
        // The scan's RMS radius: the lever arm that makes rotation comparable
        // with translation in the degeneracy analysis.
        let lever = (points
            .iter()
            .map(|p| p[0] * p[0] + p[1] * p[1])
            .sum::<f64>()
            / points.len() as f64)
            .sqrt();
        let mut pose = guess;
        let mut iterations = 0;
        let mut outcome = None;
        let mut stack: Vec<(usize, Arc<Distributions>)> = Vec::with_capacity(levels);
        let mut memo = LevelMemo::default();
        let mut pairs = MatchPairs::new(points, None, options);
        for level in (0..levels).rev() {
            // A skipped level between the coarsest and the fine one: the
            // stages around it pair with each other instead.
            if level != 0 && level + 1 != levels && options.skip_levels >> level & 1 == 1 {
                continue;
            }
            let Some(dists) = self.distributions(level, options.dist_options()) else {
                break;
            };
            let cell = dists.cell_size();
            let mut solver = options.solver_options(cell, level);
            stack.push((level, dists));
            if stack.len() > LEVEL_WINDOW {
                stack.remove(0);
            }
            // Not on the first stage: its start may be far off, and pairs
            // found there would misjudge the geometry.
            if options.freeze_unconstrained && level + 1 < levels {
                if let Some((coarse, d)) = stack.first() {
                    // Usually computed where the stage before ended.
                    let info = memo.information(*coarse, pose).unwrap_or_else(|| {
                        point_to_plane_information(own_cell_pairs(d, points, pose), pose)
                    });
                    solver.projector = constrained_projector(&info, lever, options.freeze_ratio);
                }
            }
            // From the second stage on, the coarser level of the window is
            // its quadratic model about the stage's start (crate::quadratic).
            let model = match stack.as_slice() {
                [coarse, _] if options.coarse_model => {
                    let terms = exact_terms(
                        std::slice::from_ref(coarse),
                        &mut pairs,
                        pose,
                        options,
                        &mut memo,
                    );
                    Some(QuadraticModel::new(pose, &terms))
                }
                _ => None,
            };
            // The levels scored point by point: with the model, the stage's own.
            let scored = if model.is_some() {
                &stack[stack.len() - 1..]
            } else {
                &stack[..]
            };
            let mut objective = |p: Pose2, order: Order| {
                let mut t = stack_terms(scored, &mut pairs, p, options, order, Some(&mut memo));
                if let Some(m) = &model {
                    let coarse = m.terms(p);
                    t.add_terms(&coarse);
                    t.matched = t.matched.max(coarse.matched);
                }
                t
            };
            let mut solved = minimise(pose, &solver, &mut objective);
            // The first (coarsest) stage also starts from the guess rotated
            // by ± `rotation_search` and keeps the best score: Newton alone
            // rarely turns a scan by more than a few degrees. Above the fine
            // level the rotated starts are first solved on centroids of the
            // scan's runs of points (crate::reduce, see CANDIDATE_VOXEL), and
            // only a start that lands above the best score so far is solved
            // on every point.
            // Above the fine level, only when the solve from the guess leaves
            // points unexplained (see MatchOptions::rotation_gate).
            let unexplained =
                level == 0 || solved.terms.score < options.rotation_gate * points.len() as f64;
            if level + 1 == levels && options.rotation_search > 0.0 && unexplained {
                // On the fine level (a one-level match) every point counts.
                let voxel = if level > 0 {
                    CANDIDATE_VOXEL * cell
                } else {
                    0.0
                };
                let few = voxel_runs(points, voxel);
                let mut few_pairs = MatchPairs::new(&few.points, Some(&few.weights), options);
                let mut rough = |p: Pose2, order: Order| {
                    stack_terms(&stack, &mut few_pairs, p, options, order, None)
                };
                for sign in [-1.0, 1.0] {
                    let start =
                        Pose2::new(pose.x, pose.y, pose.theta + sign * options.rotation_search);
                    let landed = minimise(start, &solver, &mut rough);
                    iterations += landed.iterations;
                    if level == 0 {
                        if landed.terms.score > solved.terms.score {
                            solved = landed;
                        }
                        continue;
                    }
                    if objective(landed.pose, Order::Value).score <= solved.terms.score {
                        continue;
                    }
                    let candidate = minimise(landed.pose, &solver, &mut objective);
                    iterations += candidate.iterations;
                    if candidate.terms.score > solved.terms.score {
                        solved = candidate;
                    }
                }
            }
            iterations += solved.iterations;
            pose = solved.pose;
            if model.is_some() && level == 0 {
                // The final score and Hessian exactly, both levels scored.
                solved.terms = exact_terms(&stack, &mut pairs, pose, options, &mut memo);
            }
            outcome = Some(solved);
        }
        let Some(outcome) = outcome else {
            return Err(NdtError::InvalidOption {
                name: "levels",
                expected: "a level the grid has",
                value: levels as f64,
            });
        };
        let hessian = outcome.terms.hessian;
        let information = stack.first().map_or_else(Matrix3::zeros, |(level, d)| {
            memo.information(*level, pose).unwrap_or_else(|| {
                point_to_plane_information(own_cell_pairs(d, points, pose), pose)
            })
        });
        Ok(MatchResult {
            pose: outcome.pose,
            converged: outcome.converged,
            iterations,
            score: outcome.terms.score,
            num_matched: outcome.terms.matched,
            hessian,
            covariance: covariance_from_hessian(&hessian),
            unconstrained: unconstrained_directions(&information, lever),
        })
    }

    /// Rejects what [`NdtGrid::match_scan`] cannot match, whatever the
    /// options: a non-finite guess, no points, a non-finite point, a point
    /// beyond [`NdtGrid::coordinate_limit`].
    pub(crate) fn check_scan(&self, points: &[[f64; 2]], guess: Pose2) -> Result<()> {
        check_finite("guess", &guess.to_array())?;
        if points.is_empty() {
            return Err(NdtError::Empty { what: "points" });
        }
        check_points("points", points)?;
        let limit = self.coordinate_limit();
        match points
            .iter()
            .position(|p| p[0].abs() >= limit || p[1].abs() >= limit)
        {
            Some(index) => Err(NdtError::CellIndexOverflow {
                what: "points",
                index,
                x: points[index][0],
                y: points[index][1],
                limit,
            }),
            None => Ok(()),
        }
    }

    /// The pyramid levels a match with `options` passes over (fine level
    /// included): [`MatchOptions::levels`], or by default as many as keep
    /// the coarsest cell at most [`AUTO_COARSEST_CELL`]; an error when the
    /// grid has fewer.
    pub(crate) fn match_levels(&self, options: &MatchOptions) -> Result<usize> {
        let levels = match options.levels {
            Some(l) => l as usize,
            None => levels_up_to(self.cell_size(), AUTO_COARSEST_CELL, self.levels()),
        };
        if levels == 0 || levels > self.levels() {
            return Err(NdtError::InvalidOption {
                name: "levels",
                expected: "between 1 and the grid's number of pyramid levels",
                value: levels as f64,
            });
        }
        Ok(levels)
    }

    /// The phased adjustment of the authors' earlier paper (Kaminade et al.,
    /// ICRA 2008; §IV-B of this one): solve with each expansion `k` of
    /// `phases` in turn (e.g. 100, 10, 1), each from the previous result.
    /// Iterations add up; the rest of the result is the last phase's.
    pub fn match_phased(
        &self,
        points: &[[f64; 2]],
        guess: Pose2,
        options: &MatchOptions,
        phases: &[f64],
    ) -> Result<MatchResult> {
        check_phases(options, phases)?;
        self.check_scan(points, guess)?;
        let levels = self.match_levels(options)?;
        self.phased_checked(points, guess, options, phases, levels)
    }

    /// [`NdtGrid::match_phased`] once its input is checked
    /// ([`check_phases`] and [`NdtGrid::check_scan`] passed) on `levels`
    /// levels ([`NdtGrid::match_levels`]): the points do not change from one
    /// phase to the next, so only each phase's start is checked again.
    pub(crate) fn phased_checked(
        &self,
        points: &[[f64; 2]],
        guess: Pose2,
        options: &MatchOptions,
        phases: &[f64],
        levels: usize,
    ) -> Result<MatchResult> {
        // All phases on one thread of the pool when split (one hand-over,
        // not one a phase; see `match_checked`).
        on_pool(options.splits(points.len()), || {
            let mut pose = guess;
            let mut iterations = 0;
            let mut last = None;
            for &k in phases {
                let opts = MatchOptions {
                    expansion: k,
                    ..*options
                };
                check_finite("guess", &pose.to_array())?;
                let res = self.match_checked(points, pose, &opts, levels)?;
                iterations += res.iterations;
                pose = res.pose;
                last = Some(res);
            }
            let mut res = last.ok_or(NO_PHASES)?;
            res.iterations = iterations;
            Ok(res)
        })
    }

    /// `E(p)`, `∇(−E)` and `∇²(−E)` of eq. (1) for `points` at `pose`, without
    /// solving (score landscapes, diagnostics, finite-difference checks).
    pub fn score_terms(
        &self,
        points: &[[f64; 2]],
        pose: Pose2,
        options: &MatchOptions,
    ) -> Result<ScoreTerms> {
        self.terms_at(points, pose, options, Order::Derivatives)
    }

    /// `E(p)` of eq. (1) alone for `points` at `pose` (the same value as
    /// [`NdtGrid::score_terms`]'s, without the derivatives' cost): for
    /// comparing candidate poses.
    pub fn score(&self, points: &[[f64; 2]], pose: Pose2, options: &MatchOptions) -> Result<f64> {
        Ok(self.terms_at(points, pose, options, Order::Value)?.score)
    }

    fn terms_at(
        &self,
        points: &[[f64; 2]],
        pose: Pose2,
        options: &MatchOptions,
        order: Order,
    ) -> Result<ScoreTerms> {
        options.validate()?;
        check_finite("pose", &pose.to_array())?;
        check_points("points", points)?;
        let dists = self
            .distributions(0, options.dist_options())
            .ok_or(NdtError::Empty { what: "levels" })?;
        Ok(MatchPairs::once(points, options)
            .evaluate(&dists, pose, options, order)
            .terms)
    }
}
