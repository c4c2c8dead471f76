//! The payload structures of format version 1, in `postcard` encoding.
//!
//! They are separate from the in-memory types on purpose: they are frozen
//! with their version (see [`super`] on versioning), and listing every field
//! of the core types in the conversions makes a new field a compile error
//! here, where it must be decided how the format changes.

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

use crate::cell::CellStats;
use crate::error::{NdtError, Result};
use crate::filter::observation::CellInfo;
use crate::grid::NdtGrid;
use crate::key::CellKey;
use crate::mapper::{MapFilter, MapperOptions, RemovalCounts};

/// A grid: cell size, pyramid levels and the fine cells, sorted by key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridV1 {
    /// Cell size \[m\].
    pub cell_size: f64,
    /// Pyramid levels, fine level included.
    pub levels: u32,
    /// Every fine cell, sorted by key.
    pub cells: Vec<CellV1>,
}

/// One fine cell: its key and eq. (6) sums about its centre.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CellV1 {
    /// Column index.
    pub ix: i32,
    /// Row index.
    pub iy: i32,
    /// `M`: number of points.
    pub count: u64,
    /// `m` about the cell's centre \[m\].
    pub sum: [f64; 2],
    /// `S` about the cell's centre, row-major \[m²\].
    pub scatter: [f64; 4],
}

/// A mapper: its grid and its filter state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapperV1 {
    /// The grid.
    pub grid: GridV1,
    /// The §V filter's state.
    pub filter: FilterV1,
}

/// The state of a [`MapFilter`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FilterV1 {
    /// The options in force.
    pub options: OptionsV1,
    /// Scans inserted so far.
    pub scans: u64,
    /// The removal counters.
    pub counts: CountsV1,
    /// Every per-cell record, sorted by key.
    pub records: Vec<RecordV1>,
}

/// One per-cell record of the filter ([`CellInfo`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordV1 {
    /// Column index.
    pub ix: i32,
    /// Row index.
    pub iy: i32,
    /// Scan number of the first scan that hit the cell.
    pub first_seen: u64,
    /// Scan number of the latest scan that hit the cell.
    pub last_seen: u64,
    /// Scans that hit the cell.
    pub observations: u32,
    /// Of those, scans in which the hit came from a small cluster.
    pub small_observations: u32,
    /// Some hit came from Area 1.
    pub seen_in_area1: bool,
}

/// [`MapperOptions`], field for field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct OptionsV1 {
    pub outlier_filter: bool,
    pub edge_removal: bool,
    pub area1_confirmation: bool,
    pub backshift_rejection: bool,
    pub observation_check: bool,
    pub radial_confirmation: bool,
    pub min_range: f64,
    pub max_range: f64,
    pub reliable_range: f64,
    pub cluster_gap: f64,
    pub cluster_spacing_factor: f64,
    pub small_object_size: f64,
    pub behind_com_margin: f64,
    pub backshift_window: f64,
    pub check_interval: u32,
    pub min_observations: u32,
    pub observation_support: bool,
    pub clear_margin: f64,
    pub clear_margin_relative: f64,
    pub pass_radius: f64,
}

/// [`RemovalCounts`], field for field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct CountsV1 {
    pub behind_com_points: u64,
    pub behind_com_cells: u64,
    pub forefront_points: u64,
    pub forefront_cells: u64,
    pub backshift_points: u64,
    pub backshift_cells: u64,
    pub area1_cells: u64,
    pub observation_cells: u64,
    pub confirmation_cells: u64,
}

/// Declares the field-for-field conversions between a core type and its
/// wire twin (every field listed: a missing one does not compile).
macro_rules! twins {
    ($core:ident <=> $wire:ident { $($f:ident),* $(,)? }) => {
        impl From<&$core> for $wire {
            fn from(c: &$core) -> Self {
                let $core { $($f),* } = *c;
                Self { $($f),* }
            }
        }
        impl From<&$wire> for $core {
            fn from(w: &$wire) -> Self {
                let $wire { $($f),* } = *w;
                Self { $($f),* }
            }
        }
    };
}

twins!(MapperOptions <=> OptionsV1 {
    outlier_filter, edge_removal, area1_confirmation, backshift_rejection,
    observation_check, radial_confirmation, min_range, max_range, reliable_range,
    cluster_gap, cluster_spacing_factor, small_object_size, behind_com_margin,
    backshift_window, check_interval, min_observations, observation_support,
    clear_margin, clear_margin_relative, pass_radius,
});

twins!(RemovalCounts <=> CountsV1 {
    behind_com_points, behind_com_cells, forefront_points, forefront_cells,
    backshift_points, backshift_cells, area1_cells, observation_cells,
    confirmation_cells,
});

impl GridV1 {
    /// The wire form of `grid`.
    pub fn of(grid: &NdtGrid) -> Self {
        let cells = grid
            .cell_states()
            .iter()
            .map(|(k, s)| CellV1 {
                ix: k.ix,
                iy: k.iy,
                count: s.count,
                sum: [s.sum.x, s.sum.y],
                scatter: [
                    s.scatter[(0, 0)],
                    s.scatter[(0, 1)],
                    s.scatter[(1, 0)],
                    s.scatter[(1, 1)],
                ],
            })
            .collect();
        Self {
            cell_size: grid.cell_size(),
            levels: u32::try_from(grid.levels()).unwrap_or(u32::MAX),
            cells,
        }
    }

    /// The grid, validated (see [`NdtGrid::from_cell_states_with_levels`]).
    pub fn build(&self) -> Result<NdtGrid> {
        let states: Vec<(CellKey, CellStats)> = self
            .cells
            .iter()
            .map(|c| {
                let m = &c.scatter;
                let stats = CellStats {
                    count: c.count,
                    sum: Vector2::new(c.sum[0], c.sum[1]),
                    scatter: Matrix2::new(m[0], m[1], m[2], m[3]),
                };
                (CellKey { ix: c.ix, iy: c.iy }, stats)
            })
            .collect();
        let levels = usize::try_from(self.levels).unwrap_or(usize::MAX);
        NdtGrid::from_cell_states_with_levels(self.cell_size, levels, &states)
    }
}

impl FilterV1 {
    /// The wire form of `filter`.
    pub fn of(filter: &MapFilter) -> Self {
        let records = filter
            .cell_records()
            .iter()
            .map(|(k, c)| RecordV1 {
                ix: k.ix,
                iy: k.iy,
                first_seen: c.first_seen,
                last_seen: c.last_seen,
                observations: c.observations,
                small_observations: c.small_observations,
                seen_in_area1: c.seen_in_area1,
            })
            .collect();
        Self {
            options: filter.options().into(),
            scans: filter.scans(),
            counts: (&filter.removal_counts()).into(),
            records,
        }
    }

    /// The filter state, validated (see [`MapFilter::from_state`]).
    pub fn build(&self) -> Result<MapFilter> {
        let records: Vec<(CellKey, CellInfo)> = self
            .records
            .iter()
            .map(|r| {
                let info = CellInfo {
                    first_seen: r.first_seen,
                    last_seen: r.last_seen,
                    observations: r.observations,
                    small_observations: r.small_observations,
                    seen_in_area1: r.seen_in_area1,
                };
                (CellKey { ix: r.ix, iy: r.iy }, info)
            })
            .collect();
        MapFilter::from_state(
            (&self.options).into(),
            &records,
            self.scans,
            (&self.counts).into(),
        )
    }
}

/// `postcard` encoding of `value`.
pub fn encode<T: Serialize>(value: &T) -> Result<Vec<u8>> {
    postcard::to_stdvec(value).map_err(|e| NdtError::Encode {
        reason: e.to_string(),
    })
}

/// `postcard` decoding of the whole of `payload` (bytes left over are an
/// error too).
pub fn decode<'a, T: Deserialize<'a>>(payload: &'a [u8]) -> Result<T> {
    let (value, rest) = postcard::take_from_bytes(payload).map_err(|e| NdtError::Decode {
        reason: e.to_string(),
    })?;
    if rest.is_empty() {
        Ok(value)
    } else {
        Err(NdtError::Decode {
            reason: format!("{} bytes left over after the payload", rest.len()),
        })
    }
}
