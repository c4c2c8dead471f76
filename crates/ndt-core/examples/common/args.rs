//! The profiling examples' positional arguments.

use std::error::Error;

/// The `i`-th positional argument as a number, `default` when absent.
pub fn arg(i: usize, default: usize) -> Result<usize, Box<dyn Error>> {
    match std::env::args().nth(i) {
        Some(s) => Ok(s.parse()?),
        None => Ok(default),
    }
}
