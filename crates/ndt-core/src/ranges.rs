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
    check_scan_and_limits(ranges, angles, min_range, max_range)?;
    Ok(points_along(
        Vec::new(),
        ranges,
        angles.iter().map(|a| a.sin_cos()),
        min_range,
        max_range,
    ))
}

/// The checks of [`points_from_ranges`].
fn check_scan_and_limits(
    ranges: &[f64],
    angles: &[f64],
    min_range: f64,
    max_range: f64,
) -> Result<()> {
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
    Ok(())
}

/// The points of the valid ranges along the beams' `(sin a, cos a)`, in
/// `points`' storage.
fn points_along(
    mut points: Vec<[f64; 2]>,
    ranges: &[f64],
    directions: impl Iterator<Item = (f64, f64)>,
    min_range: f64,
    max_range: f64,
) -> Vec<[f64; 2]> {
    // Room for every beam at once: collecting a filter grows the vector
    // from a few points by doubling (6 reallocations for 180 beams, 0.5 % of
    // the odometry loop's instructions, benches/SPEED_LOG.md, session 20).
    points.clear();
    points.reserve(ranges.len());
    points.extend(
        ranges
            .iter()
            .zip(directions)
            .filter(|(r, _)| r.is_finite() && **r >= min_range && **r < max_range && **r > 0.0)
            .map(|(r, (s, c))| [r * c, r * s]),
    );
    points
}

/// The beams' `(sin a, cos a)` of the last scan's angles, kept while the
/// angles stay the same (a sensor's beams point the same way scan after
/// scan): [`BeamDirections::points`] gives [`points_from_ranges`]'s points
/// without a sine and cosine per beam and scan.
#[derive(Debug, Clone, Default)]
pub struct BeamDirections {
    angles: Vec<f64>,
    directions: Vec<(f64, f64)>,
    /// Points given back ([`BeamDirections::give_back`]): the next
    /// points' storage. A new vector a scan took the allocator's lock
    /// twice, which a mapper's helper thread may hold (benches/SPEED_LOG.md,
    /// session 27).
    spare: Vec<[f64; 2]>,
}

impl BeamDirections {
    /// [`points_from_ranges`] (the same checks and points, bit for bit).
    pub fn points(
        &mut self,
        ranges: &[f64],
        angles: &[f64],
        min_range: f64,
        max_range: f64,
    ) -> Result<Vec<[f64; 2]>> {
        check_scan_and_limits(ranges, angles, min_range, max_range)?;
        let same = self.angles.len() == angles.len()
            && self
                .angles
                .iter()
                .zip(angles)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            self.angles.clear();
            self.angles.extend_from_slice(angles);
            self.directions.clear();
            self.directions.extend(angles.iter().map(|a| a.sin_cos()));
        }
        Ok(points_along(
            std::mem::take(&mut self.spare),
            ranges,
            self.directions.iter().copied(),
            min_range,
            max_range,
        ))
    }

    /// The `(sin a, cos a)` of each angle of the last
    /// [`BeamDirections::points`] call (empty before the first).
    pub fn directions(&self) -> &[(f64, f64)] {
        &self.directions
    }

    /// Points of [`BeamDirections::points`] done with: the next call gives
    /// its points in their storage.
    pub fn give_back(&mut self, points: Vec<[f64; 2]>) {
        self.spare = points;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kept directions give `points_from_ranges`'s points bit for bit,
    /// when the angles repeat and when they change (length or value), in
    /// the storage of the points given back (longer or shorter), and the
    /// same errors.
    #[test]
    fn kept_directions_give_the_same_points() {
        let mut kept = BeamDirections::default();
        let a1: Vec<f64> = (0..181).map(|i| f64::from(i - 90).to_radians()).collect();
        let mut a2 = a1.clone();
        a2[7] += 1e-12;
        let a3: Vec<f64> = a1[..100].to_vec();
        for (k, angles) in [&a1, &a1, &a2, &a1, &a3, &a3, &a1].into_iter().enumerate() {
            let ranges: Vec<f64> = (0..angles.len())
                .map(|i| match (i + k) % 9 {
                    0 => f64::NAN,
                    1 => 0.0,
                    2 => 30.0,
                    _ => 0.1 + 0.37 * (i + k) as f64 % 25.0,
                })
                .collect();
            let want = points_from_ranges(&ranges, angles, 0.05, 30.0).unwrap_or_default();
            let got = kept.points(&ranges, angles, 0.05, 30.0).unwrap_or_default();
            assert!(!want.is_empty());
            let bits = |p: &[[f64; 2]]| -> Vec<u64> {
                p.iter()
                    .flat_map(|q| [q[0].to_bits(), q[1].to_bits()])
                    .collect()
            };
            assert_eq!(bits(&got), bits(&want), "scan {k}");
            kept.give_back(got);
        }
        let short = [1.0, 2.0];
        assert_eq!(
            kept.points(&short, &a1, 0.0, 30.0)
                .map_err(|e| e.to_string()),
            points_from_ranges(&short, &a1, 0.0, 30.0).map_err(|e| e.to_string())
        );
    }
}
