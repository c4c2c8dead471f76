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
        /// Map-frame x of the point [m].
        x: f64,
        /// Map-frame y of the point [m].
        y: f64,
        /// Largest admissible |coordinate| [m].
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
    /// A stored cell (see [`crate::NdtGrid::from_cell_states`]) that no grid
    /// can hold.
    #[error("cells: cell {index} {reason}")]
    InvalidCell {
        /// Position of the cell in the input.
        index: usize,
        /// What is wrong with it, in words.
        reason: &'static str,
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
