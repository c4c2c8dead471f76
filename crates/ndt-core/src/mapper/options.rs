//! The options of the §V elimination: a switch per step and the step's
//! parameters, with the paper's values as defaults where it gives them.

use crate::error::{check_bound, NdtError, Result};

/// Options of [`crate::Mapper`] / [`crate::MapFilter`]. Lengths in metres.
///
/// `outlier_filter = false` stores every valid point and removes nothing:
/// the unfiltered map. With it on, each step can still be switched off alone;
/// the clustering of a-1 always runs, because b-1, b-2 and d need to know
/// which clusters are small objects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapperOptions {
    /// Master switch for all of §V (default on).
    pub outlier_filter: bool,
    /// Steps a-2…a-4 (§V-B(1), "edge of object"): in each small cluster drop
    /// the points behind the centre of mass and keep only the forefront cell.
    pub edge_removal: bool,
    /// Step b-1 (§V-B(2)): at each periodic check, delete the cells of small
    /// objects never observed from Area 1.
    pub area1_confirmation: bool,
    /// Step b-2 (§V-B(2)): do not store a small-cluster point in Area 2 when
    /// the map holds a cell short of it along its beam (backward shift).
    pub backshift_rejection: bool,
    /// Step c (§V-B(3), "surface of wall"): at each periodic check, delete
    /// cells observed in fewer than `min_observations` scans.
    pub observation_check: bool,
    /// Step d (§V-B(4)): remove map cells a new beam passed through short of
    /// its hit (small objects only in Area 1, big ones everywhere).
    pub radial_confirmation: bool,
    /// Ranges below it are invalid \[m\] (default 0: only 0 is invalid).
    pub min_range: f64,
    /// Ranges at or above it are invalid, "no return" \[m\] (default ∞).
    pub max_range: f64,
    /// Area 1 / Area 2 boundary \[m\]; the paper: 0.5 m for 2 cm objects
    /// seen by a URG-04LX.
    pub reliable_range: f64,
    /// a-1: base distance \[m\] between consecutive points of one cluster.
    pub cluster_gap: f64,
    /// a-1: plus this many times the spacing of adjacent beams at the range
    /// of the points (so far walls stay whole).
    pub cluster_spacing_factor: f64,
    /// a-1: a cluster whose lateral extent is at most this \[m\] is a small
    /// object (the paper's sticks are 1.3–1.5 cm).
    pub small_object_size: f64,
    /// a-3: points more than this \[m\] behind the centre of mass are dropped
    /// (the paper: 0, "the data in back of the CoM").
    pub behind_com_margin: f64,
    /// b-2: how far short of a new point \[m\] a former cell rejects it (the
    /// paper measured a 5 cm shift; twice that by default).
    pub backshift_window: f64,
    /// b-1/c: the periodic check runs every this many scans (the paper: 3).
    pub check_interval: u32,
    /// c: cells observed in fewer scans than this are deleted at a check,
    /// once they have had `check_interval` scans to be seen.
    pub min_observations: u32,
    /// c: keep a rarely seen cell that has an established 8-neighbour (ours;
    /// a sparsely hit far wall is not speckle).
    pub observation_support: bool,
    /// d: the walk stops this far \[m\] short of the hit, or
    /// `clear_margin_relative` times the range if that is more (and more at
    /// grazing incidence: divided by `tan α` below 45°).
    pub clear_margin: f64,
    /// d: the margin as a fraction of the range (the URG-04LX is accurate
    /// to ±1 % beyond 1 m: 1.5 % is three standard deviations).
    pub clear_margin_relative: f64,
    /// d: a cell counts as passed only if the beam passes within this
    /// distance \[m\] of the mean of its points.
    pub pass_radius: f64,
}

impl Default for MapperOptions {
    fn default() -> Self {
        Self {
            outlier_filter: true,
            edge_removal: true,
            area1_confirmation: true,
            backshift_rejection: true,
            observation_check: true,
            radial_confirmation: true,
            min_range: 0.0,
            max_range: f64::INFINITY,
            reliable_range: 0.5,
            cluster_gap: 0.05,
            cluster_spacing_factor: 2.0,
            small_object_size: 0.05,
            behind_com_margin: 0.0,
            backshift_window: 0.10,
            check_interval: 3,
            min_observations: 2,
            observation_support: true,
            clear_margin: 0.03,
            clear_margin_relative: 0.015,
            pass_radius: 0.005,
        }
    }
}

impl MapperOptions {
    /// The unfiltered map: every step off.
    pub fn unfiltered() -> Self {
        Self {
            outlier_filter: false,
            ..Self::default()
        }
    }

    /// `true` when step `enabled` runs (the master switch and its own).
    pub(crate) fn on(&self, enabled: bool) -> bool {
        self.outlier_filter && enabled
    }

    /// Checks every option's range.
    pub fn validate(&self) -> Result<()> {
        let non_negative = |name: &'static str, value: f64| {
            check_bound(name, "a finite length >= 0 m", value, 0.0, false)
        };
        non_negative("min_range", self.min_range)?;
        non_negative("reliable_range", self.reliable_range)?;
        non_negative("cluster_gap", self.cluster_gap)?;
        non_negative("small_object_size", self.small_object_size)?;
        non_negative("behind_com_margin", self.behind_com_margin)?;
        non_negative("backshift_window", self.backshift_window)?;
        non_negative("clear_margin", self.clear_margin)?;
        non_negative("clear_margin_relative", self.clear_margin_relative)?;
        non_negative("pass_radius", self.pass_radius)?;
        if !(self.cluster_spacing_factor.is_finite() && self.cluster_spacing_factor >= 0.0) {
            return Err(NdtError::InvalidOption {
                name: "cluster_spacing_factor",
                expected: "a finite factor >= 0",
                value: self.cluster_spacing_factor,
            });
        }
        if self.max_range.is_nan() || self.max_range <= self.min_range {
            return Err(NdtError::InvalidOption {
                name: "max_range",
                expected: "a range > min_range (inf allowed)",
                value: self.max_range,
            });
        }
        if self.check_interval == 0 {
            return Err(NdtError::InvalidOption {
                name: "check_interval",
                expected: "an integer >= 1 (scans)",
                value: 0.0,
            });
        }
        if self.min_observations == 0 {
            return Err(NdtError::InvalidOption {
                name: "min_observations",
                expected: "an integer >= 1 (scans)",
                value: 0.0,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        assert!(MapperOptions::default().validate().is_ok());
        let bad = MapperOptions {
            reliable_range: -0.1,
            ..MapperOptions::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "reliable_range: expected a finite length >= 0 m, got -0.1"
        );
        let bad = MapperOptions {
            max_range: 0.0,
            ..MapperOptions::default()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("max_range:"));
        let bad = MapperOptions {
            check_interval: 0,
            ..MapperOptions::default()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("check_interval:"));
    }
}
