//! One scan through §V: a-1…a-4, b-2, then storing, d, and every
//! `check_interval` scans b-1 and c. Everything is decided before the map is
//! touched, so a failed call changes nothing.

use rustc_hash::FxHashSet;

use super::MapFilter;
use crate::error::{check_finite, NdtError, Result};
use crate::filter::areas::Area;
use crate::filter::backshift::former_cell_short_of;
use crate::filter::cluster::{behind_com, centre_of_mass, clusters, forefront_cell, is_small};
use crate::filter::confirmation::{cells_to_clear, grazing_margin, passed_cells, Clearing};
use crate::filter::observation::{check_due, CellInfo};
use crate::filter::walkmap::WalkMap;
use crate::filter::Beam;
use crate::grid::NdtGrid;
use crate::key::CellKey;
use crate::ranges::check_beams;
use crate::scratch::{first_touch, KeySet};
use crate::se2::Pose2;

/// A scan that passed [`MapFilter::check_scan`]: its valid beams and pose.
#[derive(Debug, Clone)]
pub(crate) struct CheckedScan {
    beams: Vec<Beam>,
    pose: Pose2,
}

impl CheckedScan {
    /// The cells the beams end in (on the lattice of cells `1 / inv_cell`
    /// wide), each once, in beam order: the cells of the same points staged
    /// by [`NdtGrid::stage`], bit for bit ([`Beam::along`] maps a point as
    /// `stage` does, and a checked beam's cell exists). `seen`: an empty
    /// set to find repeats with.
    pub(crate) fn cells(&self, inv_cell: f64, seen: &mut KeySet) -> Vec<CellKey> {
        let keys = self.beams.iter();
        first_touch(keys.map(|b| CellKey::of_flagged(b.world, inv_cell).0), seen)
    }
}

/// Which step dropped a point of the new scan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dropped {
    /// a-3: behind the centre of mass.
    BehindCom,
    /// a-4: outside the forefront cell.
    Forefront,
    /// b-2: behind a former cell in Area 2.
    Backshift,
}

impl MapFilter {
    /// Adds one laser scan seen from `pose` (`T_map_scan`, the sensor's pose)
    /// to `grid`, through the §V elimination.
    ///
    /// `ranges` \[m\] and `angles` \[rad, sensor frame\] hold one value per beam,
    /// in beam order (the order clustering follows). Beams whose range is 0,
    /// NaN, infinite, below `min_range` or at or above `max_range` are
    /// skipped. With `outlier_filter` off every other beam is stored. A scan
    /// without a valid beam changes nothing and is not counted.
    ///
    /// Errors (and changes nothing) when the lengths differ, an angle or the
    /// pose is not finite, or a hit's cell index would overflow.
    pub fn insert_scan(
        &mut self,
        grid: &mut NdtGrid,
        ranges: &[f64],
        angles: &[f64],
        pose: Pose2,
    ) -> Result<()> {
        let scan = self.check_scan(grid, ranges, angles, None, pose, None)?;
        self.insert_checked(grid, &scan)
    }

    /// [`MapFilter::insert_scan`] of a scan [`MapFilter::check_scan`] passed
    /// (for this filter's options and `grid`'s cell size).
    pub(crate) fn insert_checked(
        &mut self,
        grid: &mut NdtGrid,
        checked: &CheckedScan,
    ) -> Result<()> {
        let (beams, pose) = (checked.beams.as_slice(), checked.pose);
        // The insert and the deletions below (and a periodic check's) bring
        // the coarser levels up to date once (NdtGrid::deferral, crate/src/grid/deferral.rs).
        let mut deferred = grid.deferral();
        let grid: &mut NdtGrid = &mut deferred;
        // The records below are of this grid's cells.
        self.stale.follow(grid);
        // A scan with no valid beam (a blinded sensor, a driver sending only
        // NaN, 0 or inf) observes nothing: it changes neither the map nor the
        // filter, not even the scan counter, so a burst of them cannot age
        // young cells into step c's deletion.
        if beams.is_empty() {
            return Ok(());
        }
        let scan = self.scans + 1;
        let o = self.options;
        if !o.outlier_filter {
            let points: Vec<[f64; 2]> = beams.iter().map(|b| [b.local.x, b.local.y]).collect();
            grid.insert(&points, pose)?;
            self.scans = scan;
            return Ok(());
        }
        let inv_cell = 1.0 / grid.cell_size();
        let sensor = nalgebra::Vector2::new(pose.x, pose.y);
        let n = beams.len();
        let mut keep = vec![true; n];
        let mut small = vec![false; n];
        let mut dropped: Vec<(usize, Dropped)> = Vec::new();
        // §V step a-1: cluster the scan, select the small clusters.
        let groups = clusters(beams, o.cluster_gap, o.cluster_spacing_factor);
        for g in &groups {
            let cluster = &beams[g.clone()];
            if !is_small(cluster, o.small_object_size) {
                continue;
            }
            small[g.clone()].fill(true);
            if !o.edge_removal {
                continue;
            }
            // §V steps a-2, a-3: drop the points behind the centre of mass.
            let behind = behind_com(cluster, centre_of_mass(cluster), o.behind_com_margin);
            for (j, &b) in behind.iter().enumerate() {
                if b {
                    keep[g.start + j] = false;
                    dropped.push((g.start + j, Dropped::BehindCom));
                }
            }
            // §V step a-4: keep only the forefront cell.
            let front = forefront_cell(cluster, &keep[g.clone()], inv_cell);
            for j in 0..cluster.len() {
                let i = g.start + j;
                if keep[i] && CellKey::of(beams[i].world, inv_cell) != front {
                    keep[i] = false;
                    dropped.push((i, Dropped::Forefront));
                }
            }
        }
        // The walks of b-2 and d read the map as it was before this scan,
        // through readers kept across the beams (filter/walkmap.rs).
        let before: &NdtGrid = grid;
        let mut walks: Option<WalkMap<'_>> = None;
        // §V step b-2: a small-cluster point in Area 2 behind a former cell
        // along its beam may be shifted backward: do not store it.
        if o.backshift_rejection {
            for i in 0..n {
                if keep[i]
                    && small[i]
                    && Area::of(beams[i].range, o.reliable_range) == Area::Suspicious
                    && former_cell_short_of(
                        walks.get_or_insert_with(|| WalkMap::new(before)),
                        sensor,
                        beams[i].world,
                        o.backshift_window,
                    )
                {
                    keep[i] = false;
                    dropped.push((i, Dropped::Backshift));
                }
            }
        }
        // Vectors sized at once (here and below): each growth of a vector
        // would take the allocator's lock (benches/SPEED_LOG.md, session
        // 27).
        let mut hit: Vec<CellKey> = Vec::with_capacity(n);
        hit.extend(
            (0..n)
                .filter(|&i| keep[i])
                .filter_map(|i| CellKey::of(beams[i].world, inv_cell)),
        );
        let hit_set: FxHashSet<CellKey> = hit.iter().copied().collect();
        // §V step d: cells short of a kept hit are free space (decided
        // against the map as it was before this scan).
        let mut clear: Vec<CellKey> = Vec::new();
        if o.radial_confirmation {
            let map = walks.get_or_insert_with(|| WalkMap::new(before));
            let mut passes = Vec::new();
            let clearing = Clearing {
                pass_radius: o.pass_radius,
                reliable_range: o.reliable_range,
            };
            for g in &groups {
                let cluster = &beams[g.clone()];
                for (j, beam) in cluster.iter().enumerate() {
                    if keep[g.start + j] {
                        let base = o.clear_margin.max(o.clear_margin_relative * beam.range);
                        let margin = grazing_margin(cluster, j, sensor, base);
                        passed_cells(
                            map,
                            &self.table,
                            sensor,
                            beam.world,
                            margin,
                            clearing,
                            &mut passes,
                        );
                    }
                }
            }
            clear = cells_to_clear(&passes);
            // A cell hit by this scan is not free space.
            clear.retain(|k| !hit_set.contains(k));
        }
        // Cells in the grid that the filter has not seen (inserted into the
        // grid directly) count as established when first hit.
        let mut occupied = grid.occupancy();
        let foreign: FxHashSet<CellKey> = hit_set
            .iter()
            .filter(|k| occupied.contains(**k) && !self.table.contains_key(k))
            .copied()
            .collect();
        // Commit: the only fallible call comes first.
        let mut points: Vec<[f64; 2]> = Vec::with_capacity(n);
        points.extend(
            (0..n)
                .filter(|&i| keep[i])
                .map(|i| [beams[i].local.x, beams[i].local.y]),
        );
        grid.insert(&points, pose)?;
        let kept = (0..n).filter(|&i| keep[i]);
        for (i, key) in kept.zip(hit) {
            let info = self.table.entry(key).or_insert_with(|| {
                if foreign.contains(&key) {
                    CellInfo::established(scan, o.min_observations)
                } else {
                    CellInfo::new(scan)
                }
            });
            let area1 = Area::of(beams[i].range, o.reliable_range) == Area::Reliable;
            info.observe(scan, small[i], area1);
        }
        let removed = self.delete(grid, &clear);
        self.counts.confirmation_cells += removed as u64;
        self.count_dropped(grid, beams, &dropped, inv_cell);
        self.scans = scan;
        if check_due(scan, o.check_interval) {
            self.run_checks(grid);
        }
        Ok(())
    }

    /// The checks of [`MapFilter::insert_scan`] alone, changing nothing: the
    /// scan's valid beams, which [`MapFilter::insert_checked`] then takes
    /// without checking them again (and does not fail on: its only other
    /// failures are the grid's checks of the same points). They depend on
    /// the options and the grid's cell size alone. `directions`: the beams'
    /// `(sin a, cos a)`, when the caller keeps them (one per angle; else
    /// computed here). `spare`: a checked scan done with, whose storage
    /// the new one takes.
    pub(crate) fn check_scan(
        &self,
        grid: &NdtGrid,
        ranges: &[f64],
        angles: &[f64],
        directions: Option<&[(f64, f64)]>,
        pose: Pose2,
        spare: Option<CheckedScan>,
    ) -> Result<CheckedScan> {
        let mut beams = spare.map(|s| s.beams).unwrap_or_default();
        beams.clear();
        self.valid_beams(grid, ranges, angles, directions, pose, &mut beams)?;
        Ok(CheckedScan { beams, pose })
    }

    /// The valid beams of a scan, checked (lengths, finite angles and pose,
    /// cell indices in range, see [`MapFilter::check_scan`]), added to
    /// `beams`.
    fn valid_beams(
        &self,
        grid: &NdtGrid,
        ranges: &[f64],
        angles: &[f64],
        directions: Option<&[(f64, f64)]>,
        pose: Pose2,
        beams: &mut Vec<Beam>,
    ) -> Result<()> {
        check_beams(ranges, angles)?;
        check_finite("pose", &pose.to_array())?;
        let (lo, hi) = (self.options.min_range, self.options.max_range);
        let inv_cell = 1.0 / grid.cell_size();
        beams.reserve(ranges.len());
        let sin_cos = pose.theta.sin_cos();
        for (index, (&r, &a)) in ranges.iter().zip(angles).enumerate() {
            if !(r.is_finite() && r > 0.0 && r >= lo && r < hi) {
                continue;
            }
            let beam = match directions.and_then(|d| d.get(index)) {
                Some(&dir) => Beam::along(index, r, a, dir, pose, sin_cos),
                None => Beam::seen_from(index, r, a, pose, sin_cos),
            };
            if CellKey::of(beam.world, inv_cell).is_none() {
                return Err(NdtError::CellIndexOverflow {
                    what: "ranges",
                    index,
                    x: beam.world.x,
                    y: beam.world.y,
                    limit: grid.coordinate_limit(),
                });
            }
            beams.push(beam);
        }
        Ok(())
    }

    /// Adds the dropped points, and the distinct cells they would have
    /// created (not in the map after the scan), to the counters.
    fn count_dropped(
        &mut self,
        grid: &NdtGrid,
        beams: &[Beam],
        dropped: &[(usize, Dropped)],
        inv_cell: f64,
    ) {
        let mut cells: [FxHashSet<CellKey>; 3] = Default::default();
        for &(i, step) in dropped {
            let slot = match step {
                Dropped::BehindCom => {
                    self.counts.behind_com_points += 1;
                    0
                }
                Dropped::Forefront => {
                    self.counts.forefront_points += 1;
                    1
                }
                Dropped::Backshift => {
                    self.counts.backshift_points += 1;
                    2
                }
            };
            if let Some(key) = CellKey::of(beams[i].world, inv_cell) {
                if grid.stats(key).is_none() {
                    cells[slot].insert(key);
                }
            }
        }
        self.counts.behind_com_cells += cells[0].len() as u64;
        self.counts.forefront_cells += cells[1].len() as u64;
        self.counts.backshift_cells += cells[2].len() as u64;
    }
}
