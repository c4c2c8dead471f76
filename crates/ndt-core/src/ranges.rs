//! Polar laser readings to scan-frame points, skipping invalid ranges.

use crate::error::{check_finite, NdtError, Result};

/// Checks that `angles` has one finite value per range.
pub fn check_beams(ranges: &[f64], angles: &[f64]) -> Result<()> {
    if ranges.len() != angles.len() {
        return Err(NdtError::LengthMismatch {
            what: "angles",
            expected: ranges.len(),
            got: angles.len(),
        });
    }
    check_finite("angles", angles)
}

/// Scan-frame points `(r cos a, r sin a)` \[m\] of the beams whose range is
/// valid: finite and `min_range ≤ r < max_range` (so 0, NaN, ∞ and readings at
/// the sensor's maximum, which mean "no return", are skipped).
///
/// Errors when `ranges` and `angles` differ in length, an angle is not
/// finite, or the range limits are not `0 ≤ min_range < max_range`.
pub fn points_from_ranges(
    ranges: &[f64],
    angles: &[f64],
    min_range: f64,
    max_range: f64,
) -> Result<Vec<[f64; 2]>> {
    check_beams(ranges, angles)?;
    if !(min_range.is_finite() && min_range >= 0.0) {
        return Err(NdtError::InvalidOption {
            name: "min_range",
            expected: "a finite range >= 0 m",
            value: min_range,
        });
    }
    if max_range.is_nan() || max_range <= min_range {
        return Err(NdtError::InvalidOption {
            name: "max_range",
            expected: "a range > min_range",
            value: max_range,
        });
    }
    Ok(ranges
        .iter()
        .zip(angles)
        .filter(|(r, _)| r.is_finite() && **r >= min_range && **r < max_range && **r > 0.0)
        .map(|(r, a)| {
            let (s, c) = a.sin_cos();
            [r * c, r * s]
        })
        .collect())
}
