//! The map a robot navigates with: an [`NdtGrid`] fed scan by scan through
//! the elimination of false detections of §V (see [`crate::filter`]).
//!
//! [`MapFilter`] holds the filter's state and works on a grid it is handed,
//! so that a caller can keep the grid elsewhere (the Python binding shares it
//! with `ndtgrid.NdtGrid`); [`Mapper`] owns both.

mod counts;
mod options;
mod pipeline;
mod restore;
mod stale;

pub(crate) use pipeline::CheckedScan;

pub use counts::RemovalCounts;
pub use options::MapperOptions;
pub use restore::MAX_COUNTER;

use crate::error::Result;
use crate::filter::areas::unconfirmed_small;
use crate::filter::objects::{group_objects, SmallObject};
use crate::filter::observation::{rarely_seen, CellInfo, CellTable};
use crate::grid::{NdtGrid, RemovalStamp};
use crate::key::CellKey;
use crate::se2::Pose2;
use stale::StaleRecords;

/// The state of the §V elimination for one map: per-cell observation
/// records, the scan counter and the removal counters.
#[derive(Debug, Clone)]
pub struct MapFilter {
    options: MapperOptions,
    table: CellTable,
    scans: u64,
    counts: RemovalCounts,
    /// The records that may have lost their cell since the last check.
    stale: StaleRecords,
}

impl MapFilter {
    /// A filter with `options` (validated) and no scans yet.
    pub fn new(options: MapperOptions) -> Result<Self> {
        options.validate()?;
        Ok(Self {
            options,
            table: CellTable::default(),
            scans: 0,
            counts: RemovalCounts::default(),
            stale: StaleRecords::default(),
        })
    }

    /// The options in force.
    pub fn options(&self) -> &MapperOptions {
        &self.options
    }

    /// Number of scans inserted so far.
    pub fn scans(&self) -> u64 {
        self.scans
    }

    /// What each step removed so far.
    pub fn removal_counts(&self) -> RemovalCounts {
        self.counts
    }

    /// Number of cells the filter keeps a record of (each at most once; the
    /// records of cells that left the grid go at the next periodic check).
    pub fn tracked_cells(&self) -> usize {
        self.table.len()
    }

    /// The filter's record of cell `key`, if a filtered scan hit it.
    pub fn cell_info(&self, key: CellKey) -> Option<&CellInfo> {
        self.table.get(&key)
    }

    /// The cells of `grid` that belong to small objects (a-1), sorted.
    pub fn small_cells(&self, grid: &NdtGrid) -> Vec<CellKey> {
        let mut keys: Vec<CellKey> = self
            .table
            .iter()
            .filter(|(k, c)| c.is_small() && grid.stats(**k).is_some())
            .map(|(&k, _)| k)
            .collect();
        keys.sort_unstable();
        keys
    }

    /// The detected small objects: the small-object cells grouped by
    /// contact, each with its centre of mass (see [`group_objects`]).
    pub fn small_objects(&self, grid: &NdtGrid) -> Vec<SmallObject> {
        group_objects(grid, &self.small_cells(grid))
    }

    /// Runs the periodic checks (b-1, then c) now, as they run after every
    /// `check_interval`-th scan; e.g. to tidy a map after its last scan.
    /// Cells too young for step c are left alone. Returns the number of
    /// cells deleted.
    pub fn run_checks(&mut self, grid: &mut NdtGrid) -> usize {
        // Both steps' deletions bring the coarser levels up to date once.
        let mut deferred = grid.deferral();
        let grid: &mut NdtGrid = &mut deferred;
        // Forget cells that left the grid by other means (asked of the
        // grid's occupancy mask, not its sums: the keys the mapper removed,
        // or the whole table when something else removed cells).
        self.stale.forget(&mut self.table, grid);
        let mut removed = 0;
        if self.options.on(self.options.area1_confirmation) {
            let keys = unconfirmed_small(&self.table);
            let n = self.delete(grid, &keys);
            self.counts.area1_cells += n as u64;
            removed += n;
        }
        if self.options.on(self.options.observation_check) {
            let keys = rarely_seen(
                &self.table,
                self.scans,
                self.options.check_interval,
                self.options.min_observations,
                self.options.observation_support,
            );
            let n = self.delete(grid, &keys);
            self.counts.observation_cells += n as u64;
            removed += n;
        }
        removed
    }

    /// Removes `keys` from the grid and the table; returns how many cells
    /// the grid lost.
    fn delete(&mut self, grid: &mut NdtGrid, keys: &[CellKey]) -> usize {
        for k in keys {
            self.table.remove(k);
        }
        let before = grid.removal_stamp();
        let n = grid.remove_cells(keys);
        self.stale.deleted(before, n);
        n
    }

    /// The mapper removed `keys` from `grid` (`n` cells, its stamp
    /// `before`); their records go with the next periodic check.
    fn mapper_removed(&mut self, before: RemovalStamp, keys: &[CellKey], n: usize) {
        self.stale.removed(before, keys, n, self.table.len());
    }
}

/// An [`NdtGrid`] with the §V elimination in front of it.
///
/// ```
/// use ndt_core::{Mapper, MapperOptions, Pose2};
/// let mut mapper = Mapper::new(0.02, MapperOptions::default()).unwrap();
/// let angles: Vec<f64> = (0..181).map(|i| (f64::from(i) - 90.0).to_radians()).collect();
/// let ranges = vec![2.0; 181];
/// mapper.insert_scan(&ranges, &angles, Pose2::identity()).unwrap();
/// assert!(!mapper.grid().is_empty());
/// ```
#[derive(Debug, Clone)]
pub struct Mapper {
    grid: NdtGrid,
    filter: MapFilter,
}

impl Mapper {
    /// An empty map of `cell_size` \[m\] cells (the paper: 0.02) with `options`.
    pub fn new(cell_size: f64, options: MapperOptions) -> Result<Self> {
        Ok(Self {
            grid: NdtGrid::new(cell_size)?,
            filter: MapFilter::new(options)?,
        })
    }

    /// Adds one scan (see [`MapFilter::insert_scan`]).
    pub fn insert_scan(&mut self, ranges: &[f64], angles: &[f64], pose: Pose2) -> Result<()> {
        self.filter
            .insert_scan(&mut self.grid, ranges, angles, pose)
    }

    /// The checks of [`Mapper::insert_scan`], changing nothing (see
    /// [`MapFilter::check_scan`]; `spare`'s storage reused).
    pub(crate) fn check_scan(
        &self,
        ranges: &[f64],
        angles: &[f64],
        directions: Option<&[(f64, f64)]>,
        pose: Pose2,
        spare: Option<CheckedScan>,
    ) -> Result<CheckedScan> {
        self.filter
            .check_scan(&self.grid, ranges, angles, directions, pose, spare)
    }

    /// Adds a scan [`Mapper::check_scan`] passed, on this mapper or on one
    /// with the same options and cell size (see [`MapFilter::insert_checked`]).
    pub(crate) fn insert_checked(&mut self, checked: &CheckedScan) -> Result<()> {
        self.filter.insert_checked(&mut self.grid, checked)
    }

    /// The map matched against.
    pub fn grid(&self) -> &NdtGrid {
        &self.grid
    }

    /// A mapper of `grid` and the filter state `filter` (e.g. as taken
    /// apart by [`Mapper::into_parts`], or loaded by [`crate::persist`]).
    pub fn from_parts(grid: NdtGrid, filter: MapFilter) -> Self {
        Self { grid, filter }
    }

    /// The grid and the filter state, taken apart.
    pub fn into_parts(self) -> (NdtGrid, MapFilter) {
        (self.grid, self.filter)
    }

    /// The filter state.
    pub fn filter(&self) -> &MapFilter {
        &self.filter
    }

    /// Keys of the occupied cells (every cell of the grid), sorted.
    pub fn occupied_cells(&self) -> Vec<CellKey> {
        let mut keys: Vec<CellKey> = self.grid.keys().collect();
        keys.sort_unstable();
        keys
    }

    /// The detected small objects (see [`MapFilter::small_objects`]).
    pub fn small_objects(&self) -> Vec<SmallObject> {
        self.filter.small_objects(&self.grid)
    }

    /// What each step removed so far.
    pub fn removal_counts(&self) -> RemovalCounts {
        self.filter.removal_counts()
    }

    /// Removes the cells `keys` from the map (see [`NdtGrid::remove_cells`]);
    /// their filter records go with the next periodic check.
    pub fn remove_cells(&mut self, keys: &[CellKey]) -> usize {
        let before = self.grid.removal_stamp();
        let n = self.grid.remove_cells(keys);
        self.filter.mapper_removed(before, keys, n);
        n
    }

    /// Keys done with: the grid's next updates keep their results in that
    /// storage (see [`NdtGrid::give_back`]).
    pub(crate) fn give_back(&mut self, keys: Vec<CellKey>) {
        self.grid.give_back(keys);
    }

    /// Runs the periodic checks now (see [`MapFilter::run_checks`]).
    pub fn run_checks(&mut self) -> usize {
        self.filter.run_checks(&mut self.grid)
    }

    /// This mapper with its grid's coarser levels brought up to date once,
    /// when the batch is dropped, instead of after every change (see
    /// [`NdtGrid::deferral`]): for runs of inserts and removals that
    /// read nothing but the fine level meanwhile.
    pub(crate) fn batch(&mut self) -> MapperBatch<'_> {
        self.grid.begin_deferral();
        MapperBatch { mapper: self }
    }
}

/// A [`Mapper`] in a batch (see [`Mapper::batch`]).
pub(crate) struct MapperBatch<'a> {
    mapper: &'a mut Mapper,
}

impl Drop for MapperBatch<'_> {
    fn drop(&mut self) {
        self.mapper.grid.end_deferral();
    }
}

impl std::ops::Deref for MapperBatch<'_> {
    type Target = Mapper;
    fn deref(&self) -> &Mapper {
        self.mapper
    }
}

impl std::ops::DerefMut for MapperBatch<'_> {
    fn deref_mut(&mut self) -> &mut Mapper {
        self.mapper
    }
}
