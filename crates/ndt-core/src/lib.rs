//! # ndt-core
//!
//! The algorithms of ndtgrid, free of Python: a sparse high-resolution NDT
//! grid map and Newton scan matching after Takubo et al., "NDT Scan Matching
//! Method for High Resolution Grid Map" (IROS 2009), building on Biber &
//! Strasser (IROS 2003).
//!
//! - [`NdtGrid`]: cells keep `M, m, S` (eq. 6) and give eq. (7) distributions;
//! - [`NdtGrid::match_scan`]: Newton's method on the score of eq. (1) with
//!   analytic per-point gradient and Hessian (eq. 3–5) and the small-cell fixes
//!   of §IV-A (neighbour search, expansion by `k` of eq. 8, minority fusion);
//! - [`Mapper`] / [`MapFilter`]: the elimination of false detections of §V
//!   (sub-grid objects, wall speckle, moved objects) in front of the grid,
//!   one step per file under [`filter`];
//! - [`persist`]: `save` / `load` / `to_bytes` / `from_bytes` of grids and
//!   mappers in a versioned, checksummed file.
//!
//! Units: metres and radians. Poses are `T_map_scan` (see [`Pose2`]).
#![deny(missing_docs)]
#![warn(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod affinity;
pub mod batch;
pub mod cell;
pub mod cellmask;
pub mod degeneracy;
pub mod directmemo;
pub mod distributions;
pub mod error;
pub mod filter;
pub mod freespace;
pub mod gather;
pub mod grid;
pub mod information;
pub mod kernels;
pub mod key;
pub mod lanexp;
mod many;
pub mod mapper;
pub mod mapworker;
pub mod matcher;
pub mod memo;
pub mod moments;
pub mod neighbor;
pub mod occupancy;
pub mod odometry;
pub mod pairs;
mod parity;
pub mod persist;
pub mod pyramid;
pub mod quadratic;
pub mod ranges;
pub mod reduce;
pub mod score;
mod scratch;
pub mod se2;
pub mod shape;
pub mod shaped;
pub mod solver;
mod spare;
mod staging;
pub mod table;
#[cfg(test)]
mod testing;
pub mod tiledir;
// The integration tests' fixtures (`tests/common`) name the crate `ndt_core`;
// unit tests that share them need the name too.
#[cfg(test)]
extern crate self as ndt_core;
pub mod window;

pub use cell::{CellStats, Gaussian};
pub use error::{NdtError, Result};
pub use filter::objects::SmallObject;
pub use freespace::{FreeSpace, Raster};
pub use grid::{CellRecord, NdtGrid};
pub use key::{CellKey, KeyBounds};
pub use mapper::{MapFilter, Mapper, MapperOptions, RemovalCounts};
pub use mapworker::MapperView;
pub use matcher::{MatchOptions, MatchResult};
pub use nalgebra;
pub use odometry::{Odometry, OdometryConfig, StepOutcome};
pub use ranges::points_from_ranges;
pub use score::{Order, ScoreTerms};
pub use se2::{wrap_angle, Pose2};
pub use solver::SolverOptions;
