//! §V of the paper: recognition of sub-grid objects and elimination of false
//! detections, one step per file. The [`crate::mapper`] runs them in order on
//! every scan:
//!
//! | step | file | what it does |
//! |---|---|---|
//! | a-1…a-4 | [`cluster`] | cluster the scan; for small clusters take the centre of mass, drop the points behind it, keep only the forefront cell |
//! | Area 1 / 2, b-1 | [`areas`] | the 0.5 m reliable range; small-object cells never observed in Area 1 are deleted |
//! | b-2 | [`backshift`] | a small-object point in Area 2 behind a map cell along its beam is not stored (backward shift) |
//! | c | [`observation`] | cells observed in fewer than 2 scans are deleted, checked every third scan |
//! | d | [`confirmation`] | cells a new beam passed through short of its hit are free space and removed |
//!
//! [`raywalk`] is the cell traversal along a beam that b-2 and d share,
//! [`walkmap`] the map as one scan's walks read it, and
//! [`objects`] groups the small-object cells into detected objects.

use nalgebra::Vector2;

pub mod areas;
pub mod backshift;
pub mod cluster;
pub mod confirmation;
pub mod objects;
pub mod observation;
pub mod raywalk;
pub mod walkmap;

/// One valid beam of a scan, in beam order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// Index of the beam in the scan's `ranges`/`angles` arrays.
    pub index: usize,
    /// Measured range \[m\].
    pub range: f64,
    /// Beam angle in the sensor frame \[rad\].
    pub angle: f64,
    /// The hit in the sensor frame, `(r cos a, r sin a)` \[m\].
    pub local: Vector2<f64>,
    /// The hit in the map frame \[m\].
    pub world: Vector2<f64>,
}

impl Beam {
    /// A beam of range `range` \[m\] and angle `angle` \[rad\] seen from the
    /// sensor pose `pose` (`T_map_scan`).
    pub fn new(index: usize, range: f64, angle: f64, pose: crate::Pose2) -> Self {
        Self::seen_from(index, range, angle, pose, pose.theta.sin_cos())
    }

    /// [`Beam::new`] with the pose's `(sin θ, cos θ)` given (the same for
    /// every beam of a scan).
    #[inline]
    pub fn seen_from(
        index: usize,
        range: f64,
        angle: f64,
        pose: crate::Pose2,
        pose_sin_cos: (f64, f64),
    ) -> Self {
        Self::along(index, range, angle, angle.sin_cos(), pose, pose_sin_cos)
    }

    /// [`Beam::seen_from`] with the beam's own `(sin a, cos a)` given (a
    /// sensor's beams point the same way scan after scan, so a loop keeps
    /// them: [`crate::ranges::BeamDirections`]).
    #[inline]
    pub fn along(
        index: usize,
        range: f64,
        angle: f64,
        (s, c): (f64, f64),
        pose: crate::Pose2,
        pose_sin_cos: (f64, f64),
    ) -> Self {
        let local = Vector2::new(range * c, range * s);
        Self {
            index,
            range,
            angle,
            local,
            world: pose.transform_with(pose_sin_cos, local),
        }
    }
}

/// The keys of the entries of `cells` that pass `keep`, sorted (the steps
/// report the cells they delete in key order, so runs are deterministic).
pub(crate) fn sorted_keys<V>(
    cells: impl IntoIterator<Item = (crate::key::CellKey, V)>,
    mut keep: impl FnMut(crate::key::CellKey, &V) -> bool,
) -> Vec<crate::key::CellKey> {
    let mut out: Vec<crate::key::CellKey> = cells
        .into_iter()
        .filter(|(k, v)| keep(*k, v))
        .map(|(k, _)| k)
        .collect();
    out.sort_unstable();
    out
}
