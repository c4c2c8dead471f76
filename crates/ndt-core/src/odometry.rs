//! A scan-to-map odometry loop: per scan, predict the pose from a motion
//! prior, match the scan against the map (§III-A with the fixes of §IV-A),
//! and add it to the map when the robot has moved enough.
//!
//! Every change to the maps goes through one private function,
//! `Odometry::insert_points` (behind [`Odometry::update_map`], and called by
//! [`Odometry::step`] with the points it already has), so the map can be
//! swapped for one with the §V outlier elimination without touching the loop.
//!
//! **Memory bound.** The grid is sparse, so it grows with the mapped area; an
//! odometry without loop closure also re-maps a place it comes back to with
//! its accumulated drift, so that area grows with the trajectory. With
//! [`OdometryConfig::map_window`] `= W > 0` the map keeps only the cells hit
//! by the last `W` inserted scans (a cell hit again is kept, with all its
//! points): at most `W × B` cells for `B`-beam scans, whatever the length of
//! the run ([`crate::window`]); the grid the loop matches against likewise
//! with [`OdometryConfig::match_map_window`]. Besides the grids the loop
//! keeps `3 × 8` bytes per scan (the poses) and the windows' cell keys.

use std::collections::VecDeque;

use crate::error::{check_bound, check_finite, NdtError, Result};
use crate::grid::{NdtGrid, StagedScan};
use crate::mapper::{Mapper, MapperOptions};
use crate::mapworker::{Hosting, MapperHost, MapperView};
use crate::matcher::{levels_up_to, MatchOptions, MatchResult};
use crate::ranges::BeamDirections;
use crate::se2::Pose2;
use crate::window::CellWindow;

/// The default [`OdometryConfig::coarse_rotation_gate`].
pub const DEFAULT_ROTATION_GATE: f64 = 0.8;

/// σ floor \[m\] of the loop's matcher (see [`OdometryConfig::matcher`]).
pub const ODOMETRY_SIGMA_FLOOR: f64 = 0.005;

/// Newton step below which the loop's matches stop on the fine level \[m\]
/// ([`MatchOptions::translation_tolerance`]; coarser levels scale it by their
/// cell size, as every match does). A match alone stops at 0.1 mm; the loop
/// stops at 0.3 mm, far below its 2 cm cells and the 25–45 mm relation
/// errors of the benchmark logs, and takes about a tenth fewer instructions
/// (callgrind, first 3000 Intel scans without the mapper: 2.85 G → 2.54 G).
/// Relation errors on the five benchmark logs with their odometry, 0.1 mm
/// against 0.3 mm: Intel 0.028 / 0.028 m, ACES 0.040 / 0.040, FR079 0.025 /
/// 0.025, MIT CSAIL 0.030 / 0.029, MIT Killian 0.042 / 0.044 (largest
/// errors ACES 0.21 / 0.34 m, MIT Killian 0.52 / 0.88 m). The loop is
/// chaotic: 0.095, 0.105 or 0.11 mm instead of 0.1 mm already moved ACES and
/// MIT Killian by up to 1 mm and their largest errors to 0.29–0.32 /
/// 0.51–1.28 m (benches/SPEED_LOG.md, session 16). 0.5 mm took ACES past
/// that spread (0.043 ± 0.052 m, largest 0.80 m).
pub const ODOMETRY_TRANSLATION_TOLERANCE: f64 = 3e-4;

/// Pyramid levels the loop's matches pass over ([`MatchOptions::skip_levels`]):
/// the 4 cm level. The loop then matches on 32, 16, 8 and 2 cm cells, the
/// final stage pairing the 2 cm cells with the 8 cm level's model. The 4 cm
/// level was 26 % of the distributions the matching grid's updates compute
/// and 3.4 of the 13.2 evaluations of a scan: the loop's own instructions,
/// first 3000 Intel scans, 2.49 → 2.06 G without the mapper (−17 %). Relation
/// errors on the five benchmark logs with their odometry stayed within the
/// loop's own run-to-run spread (fine-level tolerances 0.28–0.32 mm: Intel
/// 0.028–0.029 m, ACES 0.039–0.045 m against 0.040–0.046 m with every level,
/// FR079 0.025, MIT CSAIL 0.029, MIT Killian 0.042–0.044 against 0.042–0.044
/// m; the largest errors in the same ranges), and without odometry ACES and
/// MIT Killian did better, MIT CSAIL 3 mm worse (benches/SPEED_LOG.md,
/// session 17). Skipping 16 cm instead kept the errors too but saves less;
/// skipping 8 cm (ACES 0.042 ± 0.044 m, largest 0.63 m) or 4 and 16 cm
/// together (ACES largest 0.96 m, MIT Killian 1.79 m) did worse in single
/// runs and was not pursued. Since session 18 also the default of every
/// match ([`crate::matcher::DEFAULT_SKIP_LEVELS`]).
pub const ODOMETRY_SKIP_LEVELS: u32 = crate::matcher::DEFAULT_SKIP_LEVELS;

/// Largest coarsest-level cell \[m\] of the loop's matches when
/// [`MatchOptions::levels`] is `None` (see [`OdometryConfig::matcher`]): 5
/// levels on 2 cm cells, where a match alone takes 6 (up to
/// [`crate::matcher::AUTO_COARSEST_CELL`]).
pub const ODOMETRY_COARSEST_CELL: f64 = 0.32;

/// Most rotations tried on each side of the prediction by the rotation search.
const MAX_ROTATION_CANDIDATES: f64 = 1000.0;

/// Accepted matches whose score per point [`OdometryConfig::coarse_rotation_gate`]
/// takes the median of.
pub const GATE_HISTORY: usize = 32;

/// Accepted matches the loop needs before [`OdometryConfig::coarse_rotation_gate`]
/// applies: until then every match runs the rotational multi-start.
pub const GATE_MIN_HISTORY: usize = 8;

/// Settings of the loop. Units: metres and radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometryConfig {
    /// Side of the map's square cells \[m\].
    pub cell_size: f64,
    /// Beams shorter than this are skipped \[m\].
    pub min_range: f64,
    /// Beams at or beyond this are skipped ("no return", or too far to be
    /// worth a 2 cm cell) \[m\].
    pub max_range: f64,
    /// A scan is added to the map when the pose moved at least this far since
    /// the last added scan \[m\]…
    pub insert_distance: f64,
    /// …or turned at least this much \[rad\].
    pub insert_angle: f64,
    /// The map keeps the cells hit by the last `map_window` added scans
    /// (0 = keep every cell; see the module's memory bound).
    pub map_window: usize,
    /// The grid the loop matches against ([`Odometry::grid`]) has a policy
    /// of its own: it takes a scan when the pose moved at least this far
    /// since the last scan it took \[m\]… (the map above, the mapper's, is
    /// the one people use: sub-grid objects need every view of them the §V
    /// elimination can get).
    ///
    /// 0.15 m, 7.5° and a window of 130 scans (about as far back along the
    /// path as 200 scans 10 cm apart), with matches up to 32 cm cells
    /// ([`OdometryConfig::matcher`]): measured with `benches/odometry_sweep.py`
    /// on the five benchmark logs (benches/SPEED_LOG.md, session 14) against
    /// the map's own 0.1 m, 5°, 200 and 64 cm. With the logs' odometry the
    /// relation errors stayed within 1 mm (Intel 0.028 against 0.030 m, MIT
    /// Killian 0.042 against 0.045 m); without it they were lower on three
    /// logs (ACES 0.056 against 0.072 m, MIT Killian 0.049 against 0.061 m),
    /// equal on FR079 and 1 mm higher on MIT CSAIL; the matching grid's
    /// inserts and window removals, about half of the loop's own thread,
    /// came a third less often. The same policy for the mapper lost a 1 cm
    /// stick of `ndtgrid demo`.
    pub match_insert_distance: f64,
    /// …or turned at least this much \[rad\].
    pub match_insert_angle: f64,
    /// The matching grid keeps the cells hit by the last `match_map_window`
    /// scans it took (0 = every cell).
    pub match_map_window: usize,
    /// A match is used only when at least this fraction of the scan's valid
    /// points found a distribution at the solution; otherwise the pose is
    /// the prediction. In `[0, 1]`. (While the map is young, see
    /// [`OdometryConfig::bootstrap_insertions`].)
    pub min_match_ratio: f64,
    /// While the map holds fewer than this many inserted scans, a match that
    /// converged is used even below [`OdometryConfig::min_match_ratio`]
    /// (0 = never). A map of one sparse scan leaves most points without a
    /// distribution even at the right pose (SICK 1° beams on 2 cm cells:
    /// one point per cell, none to fuse with; on ACES scan 1 against scan
    /// 0, from the same place, 31 of 173 points). Without odometry the pose
    /// then stays at the prediction, the robot never seems to move far
    /// enough for a second insertion, and the loop never starts: ACES
    /// without odometry stayed at the origin (0.736 m relation error) with
    /// 0, and tracked (0.072 m) with 2. With odometry the five benchmark
    /// logs gave the same relation errors, ACES 0.039 against 0.040 m
    /// (benches/SPEED_LOG.md, session 9). Since the loop passes over the
    /// 4 cm level ([`ODOMETRY_SKIP_LEVELS`]), ACES's first match without
    /// odometry is accepted anyway and 0 and 2 give the same run (0.057 m);
    /// matching on every level, 0 still leaves it at the origin (session 17).
    /// The rule stays for maps that need it.
    pub bootstrap_insertions: usize,
    /// Half-width of the search over the predicted rotation before matching
    /// \[rad\] (0 = off): the score of eq. (1) is evaluated at the prediction
    /// turned by `±rotation_step, ±2·rotation_step, …` up to this, and Newton
    /// starts from the best. A 2 cm map's basin is narrow in rotation (1° moves
    /// a point 5 m away by 9 cm), and wheel odometry is worst in turns. Off
    /// by default since the match's own rotational multi-start
    /// ([`MatchOptions::rotation_search`], ±0.15 rad from run centroids) covers
    /// the same turns: on the five benchmark logs `±10°` in 1° steps gave the
    /// same relation errors to 0.1 mm or better (BENCHMARK.md, "Datasets") at
    /// 23–31 % more time per scan.
    pub rotation_search: f64,
    /// Step of that search \[rad\].
    pub rotation_step: f64,
    /// When the odometry prior and the constant-velocity prior differ by at
    /// least this translation \[m\] (or [`OdometryConfig::prior_gap_angle`]),
    /// the scan is matched from both and the match with the higher score of
    /// eq. (1) is kept. (The constant-velocity prior is also tried whenever
    /// the match from the odometry prior fails.) `inf` = never; 0 = always.
    pub prior_gap_distance: f64,
    /// The rotation of that gap \[rad\].
    pub prior_gap_angle: f64,
    /// When the matcher's rotational multi-start
    /// ([`MatchOptions::rotation_search`]) runs. It is the most expensive
    /// part of a match, and from a good prior it rarely changes the result;
    /// but from a poor one (no odometry, a fast turn) it is what keeps the
    /// rotation. So a scan is first matched without it and matched again
    /// with it (that result kept, see [`StepOutcome::multi_start`]) only
    /// when the first match fails [`OdometryConfig::min_match_ratio`] or its
    /// score of eq. (1) per point is below this fraction of the median of
    /// the last [`GATE_HISTORY`] accepted matches' (and for the first
    /// [`GATE_MIN_HISTORY`] accepted matches). `inf` = every scan runs the
    /// multi-start (no first try); 0 = only after a failed match. (The
    /// loop's matches with the multi-start ignore the matcher's own
    /// [`MatchOptions::rotation_gate`]: this gate decides.)
    ///
    /// 0.8 measured on the five benchmark logs (`benches/rotation_sweep.py`,
    /// benches/SPEED_LOG.md, session 9): with their odometry, mean relation errors
    /// equal to those with the multi-start on every scan or lower (MIT
    /// Killian 0.045 m against 0.048 m), in 17 % less time on Intel, with
    /// 0.3–1.6 % of the scans running the multi-start; without odometry the
    /// multi-start off altogether let MIT Killian's rotation error reach 57°,
    /// this gate 2.4°.
    pub coarse_rotation_gate: f64,
    /// The matcher's options (§IV-A). The loop's default differs from the
    /// paper's in one place: `expansion` (`k` of eq. 8) is 30, not 10 —
    /// measured on the benchmark logs (1° SICK beams, whose 2 cm cells hold
    /// few points), where it lowered the relation error (see BENCHMARK.md).
    /// The σ floor is 5 mm, not the scan-to-scan default of 1 cm: the loop
    /// matches against a map of many scans, whose cells are well sampled
    /// (the simulated demo's RMS pose error: 0.36 cm with 5 mm, 0.94 cm with
    /// 2 cm). For the same reason fine cells keep their own covariance
    /// (`shape_cell = 0`, see [`crate::shape`]), and directions are frozen
    /// only below [`crate::degeneracy::DEGENERACY_RATIO`] (see
    /// [`crate::degeneracy::FREEZE_RATIO`]). With `levels: None` it matches
    /// on as many levels as keep the coarsest cell at most
    /// [`ODOMETRY_COARSEST_CELL`] (5 levels, 2–32 cm, on 2 cm cells), not
    /// 64 cm as a match alone: from a motion prior the 64 cm stage adds
    /// little, and without odometry it made the benchmark logs' matches
    /// worse (benches/SPEED_LOG.md, session 14), and of those it passes
    /// over the 4 cm level ([`ODOMETRY_SKIP_LEVELS`]). Its Newton steps stop at
    /// [`ODOMETRY_TRANSLATION_TOLERANCE`] (0.3 mm on the fine level), not a
    /// match's 0.1 mm.
    pub matcher: MatchOptions,
    /// The §V elimination applied to every inserted scan for the map the
    /// loop builds ([`Odometry::mapper`]; on by default: `outlier_filter =
    /// true`). Its range limits are the loop's (`min_range`, `max_range`),
    /// whatever these options say. Step b (Area 2, beyond the 0.5 m reliable
    /// range of a URG-04LX, is trusted only where Area 1 confirms it) is off
    /// by default here: with a SICK in a large building nearly everything is
    /// Area 2.
    pub mapper: MapperOptions,
    /// Match against the mapper's filtered grid (the paper's way) instead of
    /// a grid of every inserted point. Off by default: on the five benchmark
    /// logs (1° SICK beams) every filtered variant matched worse — MIT
    /// Killian 0.067–0.084 m relation error against 0.048 m unfiltered (see
    /// BENCHMARK.md); the elimination is meant for the map people and
    /// planners use, which the mapper still provides.
    pub match_filtered_map: bool,
    /// Update the mapper ([`Odometry::mapper`]) on a helper thread, behind
    /// the loop, instead of in line (see [`crate::mapworker`]): the loop goes
    /// on matching while the §V elimination of the last inserted scan runs,
    /// and reading the mapper waits for it. Off: on the loop's own thread, 8
    /// inserted scans at a time, as the helper takes them (reading the
    /// mapper first takes in the rest). The poses and the mapper are the
    /// same bit for bit either way. On by default: it takes one more core
    /// (the helper sleeps when idle) and the Intel log runs in less time on
    /// 2 cores (BENCHMARK.md, "Speed"). The helper starts with the
    /// [`Odometry`] and inherits the CPU affinity of the thread that makes
    /// it (Linux): made on a thread pinned to one CPU, it shares that CPU
    /// with the loop (benches/SPEED_LOG.md, session 33). Ignored with
    /// [`OdometryConfig::match_filtered_map`] (the loop then matches against
    /// the mapper's grid, so it takes each scan at once).
    pub background_mapper: bool,
    /// Build the map at all ([`Odometry::mapper`]). Off: poses only, as a
    /// scan-to-map odometry such as KISS-ICP gives them. The loop keeps its
    /// matching grid and nothing else (no helper thread, no §V elimination,
    /// `insert_distance`, `insert_angle`, `map_window` and the mapper
    /// options unused); the poses are the same bit for bit, since they never
    /// depend on the map ([`OdometryConfig::match_filtered_map`] aside,
    /// which needs it). On the Intel log it used 50–55 % of the default's
    /// CPU time, both threads counted, and 86–103 % of its wall time
    /// (benches/SPEED_LOG.md, session 28; 37–43 % and 64–94 % in session
    /// 21).
    pub build_map: bool,
}

impl Default for OdometryConfig {
    fn default() -> Self {
        Self {
            cell_size: 0.02,
            min_range: 0.0,
            max_range: 30.0,
            insert_distance: 0.1,
            insert_angle: 5f64.to_radians(),
            map_window: 200,
            match_insert_distance: 0.15,
            match_insert_angle: 7.5f64.to_radians(),
            match_map_window: 130,
            min_match_ratio: 0.3,
            bootstrap_insertions: 2,
            rotation_search: 0.0,
            rotation_step: 1f64.to_radians(),
            prior_gap_distance: 0.1,
            prior_gap_angle: 5f64.to_radians(),
            coarse_rotation_gate: DEFAULT_ROTATION_GATE,
            matcher: MatchOptions {
                expansion: 30.0,
                sigma_floor: ODOMETRY_SIGMA_FLOOR,
                shape_cell: 0.0,
                freeze_ratio: crate::degeneracy::DEGENERACY_RATIO,
                translation_tolerance: ODOMETRY_TRANSLATION_TOLERANCE,
                skip_levels: ODOMETRY_SKIP_LEVELS,
                ..MatchOptions::default()
            },
            mapper: MapperOptions {
                backshift_rejection: false,
                ..MapperOptions::default()
            },
            match_filtered_map: false,
            background_mapper: true,
            build_map: true,
        }
    }
}

impl OdometryConfig {
    /// Checks every setting's range.
    pub fn validate(&self) -> Result<()> {
        let non_negative = |name: &'static str, value: f64| {
            check_bound(name, "a finite value >= 0", value, 0.0, false)
        };
        non_negative("insert_distance", self.insert_distance)?;
        non_negative("insert_angle", self.insert_angle)?;
        non_negative("match_insert_distance", self.match_insert_distance)?;
        non_negative("match_insert_angle", self.match_insert_angle)?;
        non_negative("min_range", self.min_range)?;
        if self.max_range.is_nan() || self.max_range <= self.min_range {
            return Err(NdtError::InvalidOption {
                name: "max_range",
                expected: "a range > min_range",
                value: self.max_range,
            });
        }
        non_negative("rotation_search", self.rotation_search)?;
        if self.coarse_rotation_gate.is_nan() || self.coarse_rotation_gate < 0.0 {
            return Err(NdtError::InvalidOption {
                name: "coarse_rotation_gate",
                expected: "a fraction >= 0 (inf = the multi-start on every scan)",
                value: self.coarse_rotation_gate,
            });
        }
        for (name, v) in [
            ("prior_gap_distance", self.prior_gap_distance),
            ("prior_gap_angle", self.prior_gap_angle),
        ] {
            if v.is_nan() || v < 0.0 {
                return Err(NdtError::InvalidOption {
                    name,
                    expected: "a value >= 0 (inf = never)",
                    value: v,
                });
            }
        }
        if !(self.rotation_step.is_finite() && self.rotation_step > 0.0)
            || self.rotation_search / self.rotation_step > MAX_ROTATION_CANDIDATES
        {
            return Err(NdtError::InvalidOption {
                name: "rotation_step",
                expected: "a finite angle > 0 rad, at least rotation_search / 1000",
                value: self.rotation_step,
            });
        }
        if !(0.0..=1.0).contains(&self.min_match_ratio) {
            return Err(NdtError::InvalidOption {
                name: "min_match_ratio",
                expected: "a fraction in [0, 1]",
                value: self.min_match_ratio,
            });
        }
        // The loop's grids have the default pyramid: refuse a level count
        // they cannot match with now, not at the second scan.
        if let Some(l) = self.matcher.levels {
            if l == 0 || l as usize > crate::grid::DEFAULT_LEVELS {
                return Err(NdtError::InvalidOption {
                    name: "levels",
                    expected: "between 1 and 6 pyramid levels (the loop's grid has 6)",
                    value: f64::from(l),
                });
            }
        }
        if self.match_filtered_map && !self.build_map {
            return Err(NdtError::ConflictingOptions {
                name: "match_filtered_map",
                other: "build_map",
                reason: "the loop would match against a map it does not build",
            });
        }
        self.matcher.validate()
    }
}

/// Whether `pose` moved at least `distance` \[m\] or turned at least
/// `angle` \[rad\] from `last` (always, with no `last`).
fn moved(last: Option<Pose2>, pose: Pose2, distance: f64, angle: f64) -> bool {
    last.is_none_or(|at| {
        let d = at.between(pose);
        d.x.hypot(d.y) >= distance || d.theta.abs() >= angle
    })
}

/// What one [`Odometry::step`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct StepOutcome {
    /// The pose of the scan (`T_map_scan`) the loop settled on.
    pub pose: Pose2,
    /// The motion prior's prediction the matcher started from: from the
    /// odometry increment when this scan and the previous one have odometry,
    /// else (or when the match from there failed and this one passed) from
    /// the last pose increment (constant velocity per scan).
    pub prediction: Pose2,
    /// The match, when there was a map and a valid point to match.
    pub matched: Option<MatchResult>,
    /// The match was used (see [`OdometryConfig::min_match_ratio`]); when
    /// `false`, `pose` is the prediction.
    pub accepted: bool,
    /// The kept match ran the matcher's rotational multi-start (see
    /// [`OdometryConfig::coarse_rotation_gate`]).
    pub multi_start: bool,
    /// The scan was added to the map.
    pub inserted: bool,
    /// Valid points of the scan (beams within the range limits).
    pub num_points: usize,
}

/// One match of [`Odometry::step`]: the result, whether it passes
/// [`OdometryConfig::min_match_ratio`], and whether it ran the multi-start.
struct Attempt {
    res: MatchResult,
    accepted: bool,
    multi_start: bool,
}

/// The scan-to-map odometry loop (see the module documentation).
#[derive(Debug, Clone)]
pub struct Odometry {
    config: OdometryConfig,
    grid: NdtGrid,
    mapper: MapperHost,
    poses: Vec<Pose2>,
    last_odom: Option<Pose2>,
    /// Where the map and the matching grid took their last scans.
    last_insert: Option<Pose2>,
    last_grid_insert: Option<Pose2>,
    /// Scans added to the map (its memory bound is kept with the mapper,
    /// [`crate::mapworker`]).
    map_insertions: u64,
    /// The matching grid's memory bound.
    grid_window: CellWindow,
    /// Score of eq. (1) per point of the last [`GATE_HISTORY`] accepted
    /// matches (see [`OdometryConfig::coarse_rotation_gate`]).
    scores: VecDeque<f64>,
    /// The beams' directions, kept from scan to scan.
    beams: BeamDirections,
    /// The last scan staged for the matching grid: the next one's storage.
    staged: StagedScan,
}

impl Odometry {
    /// An empty loop; errors on invalid settings.
    pub fn new(config: OdometryConfig) -> Result<Self> {
        config.validate()?;
        let mapper_options = MapperOptions {
            min_range: config.min_range,
            max_range: config.max_range,
            ..config.mapper
        };
        Ok(Self {
            grid: NdtGrid::new(config.cell_size)?,
            mapper: MapperHost::new(
                Mapper::new(config.cell_size, mapper_options)?,
                if !config.build_map || config.match_filtered_map {
                    Hosting::EachScan
                } else if config.background_mapper {
                    Hosting::Helper
                } else {
                    Hosting::Batches
                },
                config.map_window,
            )?,
            config,
            poses: Vec::new(),
            last_odom: None,
            last_insert: None,
            last_grid_insert: None,
            map_insertions: 0,
            grid_window: CellWindow::default(),
            scores: VecDeque::with_capacity(GATE_HISTORY + 1),
            beams: BeamDirections::default(),
            staged: StagedScan::default(),
        })
    }

    /// The settings.
    pub fn config(&self) -> &OdometryConfig {
        &self.config
    }

    /// The map the scans are matched against: every inserted point, or the
    /// mapper's filtered grid with [`OdometryConfig::match_filtered_map`].
    pub fn grid(&self) -> &NdtGrid {
        match self.mapper.inline() {
            // The filtered map's mapper is always in line (see
            // `OdometryConfig::background_mapper`).
            Some(m) if self.config.match_filtered_map => m.grid(),
            _ => &self.grid,
        }
    }

    /// The mapper (grid and §V filter) the loop builds: the map to show and
    /// navigate with. With [`OdometryConfig::background_mapper`] this waits
    /// until the helper has taken in every inserted scan, and the helper
    /// waits while the view is held. Fails with [`NdtError::NoMap`] when
    /// [`OdometryConfig::build_map`] is off.
    pub fn mapper(&self) -> Result<MapperView<'_>> {
        if !self.config.build_map {
            return Err(NdtError::NoMap);
        }
        Ok(self.mapper.view())
    }

    /// Waits until the mapper has taken in every inserted scan (with
    /// [`OdometryConfig::background_mapper`]; at once otherwise), as
    /// [`Odometry::mapper`] does before giving a view. Call it before the
    /// process forks: a forked child has no helper thread, and the scans it
    /// still held would be lost (see [`crate::mapworker`]).
    pub fn wait_for_mapper(&self) {
        self.mapper.settle();
    }

    /// The pose of every scan so far, in order.
    pub fn poses(&self) -> &[Pose2] {
        &self.poses
    }

    /// Scans added to the map so far (0 without
    /// [`OdometryConfig::build_map`]).
    pub fn insertions(&self) -> u64 {
        self.map_insertions
    }

    /// Scans the matching grid took so far
    /// ([`OdometryConfig::match_insert_distance`]; 0 with
    /// [`OdometryConfig::match_filtered_map`], which matches against the
    /// map itself).
    pub fn grid_insertions(&self) -> u64 {
        self.grid_window.scans()
    }

    /// Scans taken by the map the loop matches against.
    fn matched_insertions(&self) -> u64 {
        if self.config.match_filtered_map {
            self.insertions()
        } else {
            self.grid_insertions()
        }
    }

    /// The loop's matcher options: [`OdometryConfig::matcher`] with its
    /// level count resolved (`None`: coarsest cell at most
    /// [`ODOMETRY_COARSEST_CELL`]).
    fn matcher(&self) -> MatchOptions {
        let m = self.config.matcher;
        let levels = m.levels.unwrap_or_else(|| {
            let l = levels_up_to(
                self.config.cell_size,
                ODOMETRY_COARSEST_CELL,
                crate::grid::DEFAULT_LEVELS,
            );
            u32::try_from(l).unwrap_or(1)
        });
        MatchOptions {
            levels: Some(levels),
            ..m
        }
    }

    /// The constant-velocity prior: the last pose moved by the last pose
    /// increment (the identity before the second scan).
    fn constant_velocity(&self) -> Option<Pose2> {
        let n = self.poses.len();
        let last = *self.poses.last()?;
        let increment = match n {
            n if n >= 2 => self.poses[n - 2].between(last),
            _ => Pose2::identity(),
        };
        Some(last.compose(increment))
    }

    /// The odometry prior: the last pose moved by the odometry increment
    /// since the last scan, when both scans have odometry.
    fn odometry_prior(&self, odom: Option<Pose2>) -> Option<Pose2> {
        let last = *self.poses.last()?;
        Some(last.compose(self.last_odom?.between(odom?)))
    }

    /// Matches `points` from `prediction` (after the rotation search): with a
    /// `bar` ([`Odometry::gate_bar`]) first without the rotational
    /// multi-start, then with it when that match looks poor
    /// ([`OdometryConfig::coarse_rotation_gate`]).
    fn match_from(
        &self,
        points: &[[f64; 2]],
        prediction: Pose2,
        bar: Option<f64>,
    ) -> Result<Attempt> {
        let start = self.rotation_start(points, prediction)?;
        let full = &self.matcher();
        if let Some(bar) = bar {
            let quick = MatchOptions {
                rotation_search: 0.0,
                ..*full
            };
            let res = self.grid().match_scan(points, start, &quick)?;
            let accepted = self.passes(&res, points.len());
            if accepted && res.score / points.len() as f64 >= bar {
                return Ok(Attempt {
                    res,
                    accepted,
                    multi_start: false,
                });
            }
        }
        // The gate above decides: the matcher's own is off for this match.
        let full = &MatchOptions {
            rotation_gate: f64::INFINITY,
            ..*full
        };
        let res = self.grid().match_scan(points, start, full)?;
        Ok(Attempt {
            accepted: self.passes(&res, points.len()),
            multi_start: full.rotation_search > 0.0,
            res,
        })
    }

    /// Whether `res` passes [`OdometryConfig::min_match_ratio`] for a scan of
    /// `points` valid points (or converged on a young map, see
    /// [`OdometryConfig::bootstrap_insertions`]).
    fn passes(&self, res: &MatchResult, points: usize) -> bool {
        let ratio = res.num_matched as f64 / points as f64;
        let young = self.matched_insertions() < self.config.bootstrap_insertions as u64;
        res.num_matched > 0 && (ratio >= self.config.min_match_ratio || (young && res.converged))
    }

    /// The score per point a match without the multi-start must reach to be
    /// kept ([`OdometryConfig::coarse_rotation_gate`]); `None` when every
    /// match runs the multi-start, or has none to run.
    fn gate_bar(&self) -> Option<f64> {
        let gate = self.config.coarse_rotation_gate;
        if !(self.config.matcher.rotation_search > 0.0 && gate.is_finite())
            || self.scores.len() < GATE_MIN_HISTORY
        {
            return None;
        }
        // A copy on the stack: the history is at most GATE_HISTORY long.
        let mut copy = [0.0; GATE_HISTORY];
        let recent = &mut copy[..self.scores.len()];
        for (r, s) in recent.iter_mut().zip(&self.scores) {
            *r = *s;
        }
        let mid = recent.len() / 2;
        let (_, median, _) = recent.select_nth_unstable_by(mid, f64::total_cmp);
        Some(gate * *median)
    }

    /// Remembers the score per point of an accepted match for the gate.
    fn record_score(&mut self, res: &MatchResult, points: usize) {
        self.scores.push_back(res.score / points as f64);
        if self.scores.len() > GATE_HISTORY {
            self.scores.pop_front();
        }
    }

    /// The insertion policy: the first scan, then whenever the pose moved
    /// [`OdometryConfig::insert_distance`] or turned
    /// [`OdometryConfig::insert_angle`] since the last added scan.
    fn should_insert(&self, pose: Pose2) -> bool {
        let c = &self.config;
        moved(self.last_insert, pose, c.insert_distance, c.insert_angle)
    }

    /// The matching grid's policy: its first scan, then whenever the pose
    /// moved [`OdometryConfig::match_insert_distance`] or turned
    /// [`OdometryConfig::match_insert_angle`] since its last (never with
    /// [`OdometryConfig::match_filtered_map`]).
    fn grid_takes(&self, pose: Pose2) -> bool {
        let c = &self.config;
        !c.match_filtered_map
            && moved(
                self.last_grid_insert,
                pose,
                c.match_insert_distance,
                c.match_insert_angle,
            )
    }

    /// The start of the match: the prediction turned by the offset of the
    /// rotation search with the highest score (the prediction when off).
    fn rotation_start(&self, points: &[[f64; 2]], prediction: Pose2) -> Result<Pose2> {
        let (range, step) = (self.config.rotation_search, self.config.rotation_step);
        if range <= 0.0 {
            return Ok(prediction);
        }
        let score = |p: Pose2| self.grid().score(points, p, &self.config.matcher);
        let mut best = (score(prediction)?, prediction);
        let n = (range / step).floor() as i64;
        for i in (-n..=n).filter(|&i| i != 0) {
            let cand = Pose2::new(
                prediction.x,
                prediction.y,
                prediction.theta + i as f64 * step,
            );
            let s = score(cand)?;
            if s > best.0 {
                best = (s, cand);
            }
        }
        Ok(best.1)
    }

    /// Processes one scan: `ranges` \[m\] and `angles` \[rad\] of its beams in the
    /// sensor frame, and optionally the odometry pose of the sensor at the
    /// scan. Returns the pose and what was done.
    ///
    /// Errors (leaving the loop unchanged) when `ranges` and `angles` differ
    /// in length, an angle or `odom` is not finite, or a point lies beyond
    /// the grid's coordinate limit.
    pub fn step(
        &mut self,
        ranges: &[f64],
        angles: &[f64],
        odom: Option<Pose2>,
    ) -> Result<StepOutcome> {
        let points = self.valid_points(ranges, angles)?;
        if let Some(o) = odom {
            check_finite("odom", &o.to_array())?;
        }
        // The first pose is the odometry pose when given, else the origin.
        let cv = self.constant_velocity();
        let mut prediction = self
            .odometry_prior(odom)
            .or(cv)
            .unwrap_or_else(|| odom.unwrap_or_default());
        let mut matched = None;
        let mut pose = prediction;
        let mut accepted = false;
        let mut multi_start = false;
        if !self.grid().is_empty() && !points.is_empty() {
            // The same bar for both priors' matches.
            let bar = self.gate_bar();
            let mut best = self.match_from(&points, prediction, bar)?;
            // Odometry can stall and then jump (dropped messages): when the
            // match from its prior fails, or the two priors disagree by the
            // prior gap, also match from the constant-velocity prior and keep
            // the better passing match (higher score of eq. 1).
            let gap = |c: Pose2| {
                let d = prediction.between(c);
                d.x.hypot(d.y) >= self.config.prior_gap_distance
                    || d.theta.abs() >= self.config.prior_gap_angle
            };
            if let Some(alt) = cv.filter(|&c| c != prediction && (!best.accepted || gap(c))) {
                let other = self.match_from(&points, alt, bar)?;
                if other.accepted && (!best.accepted || other.res.score > best.res.score) {
                    (best, prediction) = (other, alt);
                }
            }
            if best.accepted {
                pose = best.res.pose;
                accepted = true;
            }
            multi_start = best.multi_start;
            matched = Some(best.res);
        }
        let inserted = self.config.build_map && !points.is_empty() && self.should_insert(pose);
        let into_grid = !points.is_empty() && self.grid_takes(pose);
        self.insert_points(&points, ranges, angles, pose, inserted, into_grid)?;
        // Nothing below can fail: the loop changes only now.
        if let Some(res) = matched.as_ref().filter(|_| accepted) {
            self.record_score(res, points.len());
        }
        self.poses.push(pose);
        if odom.is_some() {
            self.last_odom = odom;
        }
        let num_points = points.len();
        self.beams.give_back(points);
        Ok(StepOutcome {
            pose,
            prediction,
            matched,
            accepted,
            multi_start,
            inserted,
            num_points,
        })
    }

    /// Adds a scan seen from `pose` to the map and to the matching grid
    /// (insertions, then the memory bounds), as [`Odometry::step`] does when
    /// both policies take a scan (the matching grid only, without
    /// [`OdometryConfig::build_map`]). All-or-nothing: on error neither
    /// changes.
    pub fn update_map(&mut self, ranges: &[f64], angles: &[f64], pose: Pose2) -> Result<()> {
        let points = self.valid_points(ranges, angles)?;
        let into_grid = !self.config.match_filtered_map;
        let to_map = self.config.build_map;
        let done = self.insert_points(&points, ranges, angles, pose, to_map, into_grid);
        self.beams.give_back(points);
        done
    }

    /// [`Odometry::update_map`] with the scan's valid points already taken
    /// from `ranges` and `angles` (as [`Odometry::step`] has them): the one
    /// place where the maps change. The map (the mapper's) takes the scan
    /// when `to_map`, the matching grid when `into_grid` (see
    /// [`OdometryConfig::match_insert_distance`]); each then forgets what
    /// fell out of its window.
    fn insert_points(
        &mut self,
        points: &[[f64; 2]],
        ranges: &[f64],
        angles: &[f64],
        pose: Pose2,
        to_map: bool,
        into_grid: bool,
    ) -> Result<()> {
        if !(to_map || into_grid) {
            return Ok(());
        }
        check_finite("pose", &pose.to_array())?;
        // Both maps check the scan before either changes; then neither
        // insertion can fail (the mapper's only failures are its checks and
        // its grid's, on the same beams).
        let checked = if to_map {
            // Both callers took `points` from these angles just before, so
            // the kept directions are theirs.
            let directions = Some(self.beams.directions()).filter(|d| d.len() == angles.len());
            Some(self.mapper.check_scan(ranges, angles, directions, pose)?)
        } else {
            None
        };
        if into_grid {
            // The scan's cells, checked before the grid changes (the mapper
            // checked the same points on the same lattice above).
            let staged = self
                .grid
                .stage(points, pose, std::mem::take(&mut self.staged))?;
            let keys = self.grid.insert_staged(&staged);
            self.staged = staged;
            let stale = self.grid_window.record(keys, self.config.match_map_window);
            self.grid.remove_cells(&stale);
            self.grid.give_back(stale);
            self.last_grid_insert = Some(pose);
        }
        let Some(checked) = checked else {
            return Ok(());
        };
        self.map_insertions += 1;
        self.last_insert = Some(pose);
        // The mapper takes the scan, then loses the cells its window drops:
        // in line, or queued behind the loop as one job (crate::mapworker).
        self.mapper.update(checked)
    }

    fn valid_points(&mut self, ranges: &[f64], angles: &[f64]) -> Result<Vec<[f64; 2]>> {
        let (lo, hi) = (self.config.min_range, self.config.max_range);
        self.beams.points(ranges, angles, lo, hi)
    }
}
