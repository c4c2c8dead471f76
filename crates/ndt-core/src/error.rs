//! The one error type of the core. Every fallible public function returns
//! [`NdtError`]; the Python binding maps it to exceptions in one place.

use thiserror::Error;

/// Everything that can go wrong in the core. Not converging is *not* an error:
/// it is reported by [`crate::MatchResult::converged`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NdtError {
    /// A value that must be finite was NaN or infinite.
    #[error("{what}: expected finite values, got {value} at index {index}")]
    NonFinite {
        /// Which argument held the value.
        what: &'static str,
        /// Index of the first offending value (point index, or pose component).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A point lies so far away that its cell index would overflow.
    #[error(
        "{what}: point {index} at ({}, {}) m is outside the grid's range of ±{limit} m \
         (cell index would overflow)",
        Num(*.x),
        Num(*.y)
    )]
    CellIndexOverflow {
        /// Which argument held the point.
        what: &'static str,
        /// Index of the point.
        index: usize,
        /// Map-frame x of the point \[m\].
        x: f64,
        /// Map-frame y of the point \[m\].
        y: f64,
        /// Largest admissible |coordinate| \[m\].
        limit: f64,
    },
    /// An input that must hold at least one element held none.
    #[error("{what}: expected at least one point, got 0")]
    Empty {
        /// Which argument was empty.
        what: &'static str,
    },
    /// Two inputs that must have the same length do not.
    #[error("{what}: expected {expected} values (one per range), got {got}")]
    LengthMismatch {
        /// The argument whose length is wrong.
        what: &'static str,
        /// The length it must have.
        expected: usize,
        /// The length it has.
        got: usize,
    },
    /// An option outside its admissible range.
    #[error("{name}: expected {expected}, got {value}")]
    InvalidOption {
        /// The option's name as users spell it.
        name: &'static str,
        /// What was expected, in words.
        expected: &'static str,
        /// The value that came.
        value: f64,
    },
    /// Two options that cannot hold together.
    #[error("{name}: cannot be on with {other} off: {reason}")]
    ConflictingOptions {
        /// The option that needs the other, as users spell it.
        name: &'static str,
        /// The option it needs.
        other: &'static str,
        /// Why, in words.
        reason: &'static str,
    },
    /// The odometry's map was asked for, but the loop builds none
    /// ([`crate::OdometryConfig::build_map`] off).
    #[error(
        "this odometry builds no map (build_map is off): it keeps the poses and the grid it \
         matches against only"
    )]
    NoMap,
    /// A stored cell (see [`crate::NdtGrid::from_cell_states`]) that no grid
    /// can hold.
    #[error("cells: cell {index} {reason}")]
    InvalidCell {
        /// Position of the cell in the input.
        index: usize,
        /// What is wrong with it, in words.
        reason: &'static str,
    },
    /// A saved filter record (see [`crate::persist`]) that no filter state
    /// can hold.
    #[error("filter: record {index} {reason}")]
    InvalidRecord {
        /// Position of the record in the file (records are sorted by key).
        index: usize,
        /// What is wrong with it, in words.
        reason: &'static str,
    },
    /// A saved counter beyond what any real map reaches (see [`crate::persist`]).
    #[error("{name}: {value} is beyond the limit of {limit} of a saved map")]
    InvalidCounter {
        /// The counter's name.
        name: &'static str,
        /// Its saved value.
        value: u64,
        /// The largest admissible value.
        limit: u64,
    },
    /// Bytes that do not start with the magic bytes of an ndtgrid file.
    #[error("not an ndtgrid file (it does not start with the magic bytes \"NDTGRID\\0\")")]
    NotNdtFile,
    /// An ndtgrid file of the other kind (a mapper file loaded as a grid or
    /// the other way round), or of an unknown kind.
    #[error("wrong kind of ndtgrid file: expected a {expected} file, got {found}")]
    WrongKind {
        /// The kind asked for: `"grid"` or `"mapper"`.
        expected: &'static str,
        /// The kind found, in words (`"a mapper file"`, `"an unknown kind …"`).
        found: String,
    },
    /// A file format version this build cannot read.
    #[error("unsupported ndtgrid file version {found}: this build reads version {supported}")]
    UnsupportedVersion {
        /// The version in the file.
        found: u32,
        /// The version this build reads (and writes).
        supported: u32,
    },
    /// Fewer bytes than the header says the file has.
    #[error("truncated ndtgrid file: expected {expected} bytes, got {got}")]
    Truncated {
        /// The length the file must have (at least the header's, while the
        /// header itself is incomplete).
        expected: u64,
        /// The length it has.
        got: u64,
    },
    /// More bytes than the header says the file has.
    #[error(
        "ndtgrid file has {} unexpected bytes after its payload: expected {expected} bytes, \
         got {got}",
        .got - .expected
    )]
    TrailingBytes {
        /// The length the file must have.
        expected: u64,
        /// The length it has (more).
        got: u64,
    },
    /// The CRC-32 of the header and payload differs from the stored one.
    #[error(
        "corrupt ndtgrid file: checksum mismatch (stored {stored:#010x}, computed {computed:#010x})"
    )]
    ChecksumMismatch {
        /// The CRC-32 in the header.
        stored: u32,
        /// The CRC-32 of the bytes read.
        computed: u32,
    },
    /// A payload that passes the checksum but cannot be decoded (written by
    /// a faulty writer).
    #[error("corrupt ndtgrid file: cannot decode the payload: {reason}")]
    Decode {
        /// What the decoder found, in words.
        reason: String,
    },
    /// The map could not be encoded (not expected to happen: reported
    /// rather than panicking).
    #[error("cannot encode the map: {reason}")]
    Encode {
        /// What the encoder said.
        reason: String,
    },
    /// Reading or writing a file failed.
    #[error("{path}: cannot {action}: {message}")]
    Io {
        /// The file, as given.
        path: String,
        /// What was being done (`"read the file"`, `"write the file"`, …).
        action: &'static str,
        /// The operating system's error number, when there is one.
        errno: Option<i32>,
        /// The error's description (without the error number).
        message: String,
    },
    /// An error about the content of the file `path`.
    #[error("{path}: {error}")]
    InFile {
        /// The file, as given.
        path: String,
        /// What is wrong with its content.
        error: Box<NdtError>,
    },
    /// The odometry's mapper lost scans: its helper thread held them when
    /// the process forked, and the child has no such thread (flush before
    /// forking: `Odometry::wait_for_mapper`; Python's `Odometry` does).
    #[error(
        "the odometry's mapper lost {batches} batch(es) of scans: its helper thread held them \
         when the process forked"
    )]
    MapperLost {
        /// Batches of scans lost.
        batches: usize,
    },
    /// A batch of scans ([`crate::NdtGrid::match_many`],
    /// [`crate::NdtGrid::insert_many`]) with a number of poses other than one
    /// per scan.
    #[error("{what}: expected {expected} poses (one per scan), got {got}")]
    PoseCount {
        /// Which argument held the poses (`guesses`, `poses`).
        what: &'static str,
        /// The number of scans.
        expected: usize,
        /// The number of poses.
        got: usize,
    },
    /// An error about scan `index` of a batch ([`crate::NdtGrid::match_many`],
    /// [`crate::NdtGrid::insert_many`]).
    #[error("scan {index}: {error}")]
    InScan {
        /// Position of the scan in the batch.
        index: usize,
        /// What is wrong with it.
        error: Box<NdtError>,
    },
    /// A helper thread of a batch ([`crate::NdtGrid::match_many`]) ended in
    /// a panic (a bug: reported rather than passed on).
    #[error("internal error: a thread matching scans of the batch panicked: {reason}")]
    ThreadPanicked {
        /// The panic's message, when it has one.
        reason: String,
    },
    /// An output that would be larger than the stated limit.
    #[error("{what}: {size} would exceed the limit of {limit}")]
    TooLarge {
        /// What would be too large.
        what: &'static str,
        /// Its size.
        size: u64,
        /// The limit.
        limit: u64,
    },
}

/// Displays a number plainly, or in scientific notation when it is very large
/// or very small, so messages stay short.
struct Num(f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a >= 1e7 || (a > 0.0 && a < 1e-4) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

/// Result alias of the core.
pub type Result<T> = std::result::Result<T, NdtError>;

/// Fails with [`NdtError::InvalidOption`] unless `value` is finite and at
/// least `min` (strictly more when `strict`); `expected` says so in words.
pub(crate) fn check_bound(
    name: &'static str,
    expected: &'static str,
    value: f64,
    min: f64,
    strict: bool,
) -> Result<()> {
    let ok = value.is_finite() && if strict { value > min } else { value >= min };
    if ok {
        Ok(())
    } else {
        Err(NdtError::InvalidOption {
            name,
            expected,
            value,
        })
    }
}

/// Fails with [`NdtError::NonFinite`] on the first non-finite value.
pub(crate) fn check_finite(what: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(NdtError::NonFinite {
            what,
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// Fails with [`NdtError::PoseCount`] unless there is one pose (`what`)
/// per scan of a batch.
pub(crate) fn check_pose_count(what: &'static str, scans: usize, poses: usize) -> Result<()> {
    if poses == scans {
        Ok(())
    } else {
        Err(NdtError::PoseCount {
            what,
            expected: scans,
            got: poses,
        })
    }
}

/// The error of scan `index` of a batch, as [`NdtError::InScan`].
pub(crate) fn in_scan(index: usize) -> impl Fn(NdtError) -> NdtError {
    move |error| NdtError::InScan {
        index,
        error: Box::new(error),
    }
}
