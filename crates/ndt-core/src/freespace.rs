//! Free space for occupancy-grid exports (ROS `map_server` maps, images):
//! the cells the laser beams passed through on their way to a hit, found by
//! walking each beam through the lattice (Amanatides & Woo's traversal).
//!
//! This is an export aid, separate from the NDT map the matcher uses: the
//! NDT grid knows where the points are (occupied), this knows where the
//! beams went (free); everything else is unknown.

use rustc_hash::FxHashMap;

use crate::error::{check_finite, NdtError, Result};
use crate::grid::check_points;
use crate::key::CellKey;
use crate::se2::Pose2;

/// Cell value of a [`Raster`]: no beam passed and no point fell here.
pub const UNKNOWN: i8 = -1;
/// Cell value of a [`Raster`]: a beam passed through and no point fell here.
pub const FREE: i8 = 0;
/// Cell value of a [`Raster`]: a point of the map fell here.
pub const OCCUPIED: i8 = 100;

/// Sparse counts of beams through each cell of a lattice of `resolution`
/// metres (cell `(⌊x / r⌋, ⌊y / r⌋)`, as the NDT grid's).
#[derive(Debug, Clone)]
pub struct FreeSpace {
    resolution: f64,
    inv: f64,
    counts: FxHashMap<CellKey, u32>,
}

/// A dense occupancy image in the convention of ROS `nav_msgs/OccupancyGrid`:
/// row-major, row 0 at the lowest y, values [`UNKNOWN`], [`FREE`] or
/// [`OCCUPIED`].
#[derive(Debug, Clone, PartialEq)]
pub struct Raster {
    /// Map-frame position of the outer corner of cell (0, 0) (lowest x and y) \[m\].
    pub origin: [f64; 2],
    /// Side of a cell \[m\].
    pub resolution: f64,
    /// Columns (along x).
    pub width: usize,
    /// Rows (along y).
    pub height: usize,
    /// `width × height` values, row by row.
    pub data: Vec<i8>,
}

impl FreeSpace {
    /// Empty free space on a lattice of `resolution` metres.
    pub fn new(resolution: f64) -> Result<Self> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(NdtError::InvalidOption {
                name: "resolution",
                expected: "a finite cell size > 0 m",
                value: resolution,
            });
        }
        Ok(Self {
            resolution,
            inv: 1.0 / resolution,
            counts: FxHashMap::default(),
        })
    }

    /// Cell size \[m\].
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Cells crossed by at least one beam.
    pub fn len(&self) -> usize {
        self.counts.len()
    }

    /// `true` before the first beam.
    pub fn is_empty(&self) -> bool {
        self.counts.is_empty()
    }

    fn key(&self, what: &'static str, index: usize, p: [f64; 2]) -> Result<CellKey> {
        let v = nalgebra::Vector2::new(p[0], p[1]);
        CellKey::of(v, self.inv).ok_or_else(|| NdtError::CellIndexOverflow {
            what,
            index,
            x: p[0],
            y: p[1],
            limit: f64::from(crate::key::MAX_INDEX) * self.resolution,
        })
    }

    /// Adds the beams of a scan: from the sensor at `pose` (`T_map_scan`) to
    /// each scan-frame point \[m\], every cell the beam passes through counts
    /// one beam, except the cell of the hit itself. All-or-nothing: on error
    /// (non-finite input, a coordinate beyond the lattice) nothing changes.
    pub fn add_scan(&mut self, points: &[[f64; 2]], pose: Pose2) -> Result<()> {
        check_finite("pose", &pose.to_array())?;
        check_points("points", points)?;
        let origin = [pose.x, pose.y];
        let start = self.key("pose", 0, origin)?;
        let mut ends = Vec::with_capacity(points.len());
        let sin_cos = pose.theta.sin_cos();
        for (index, p) in points.iter().enumerate() {
            let w = pose.transform_with(sin_cos, nalgebra::Vector2::new(p[0], p[1]));
            ends.push(([w.x, w.y], self.key("points", index, [w.x, w.y])?));
        }
        for (end, end_key) in ends {
            self.walk(origin, start, end, end_key);
        }
        Ok(())
    }

    /// Amanatides & Woo: visits the cells from `start` along the segment
    /// `a → b`, stopping before `end` (exactly `|Δix| + |Δiy|` steps).
    fn walk(&mut self, a: [f64; 2], start: CellKey, b: [f64; 2], end: CellKey) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let axis = |d: f64, a: f64, i: i32| -> (i32, f64, f64) {
            if d > 0.0 {
                let next = (f64::from(i) + 1.0) * self.resolution;
                (1, (next - a) / d, self.resolution / d)
            } else if d < 0.0 {
                let next = f64::from(i) * self.resolution;
                (-1, (next - a) / d, -self.resolution / d)
            } else {
                (0, f64::INFINITY, f64::INFINITY)
            }
        };
        let (sx, mut tx, ddx) = axis(dx, a[0], start.ix);
        let (sy, mut ty, ddy) = axis(dy, a[1], start.iy);
        let steps = (i64::from(end.ix) - i64::from(start.ix)).unsigned_abs()
            + (i64::from(end.iy) - i64::from(start.iy)).unsigned_abs();
        let mut key = start;
        for _ in 0..steps {
            *self.counts.entry(key).or_insert(0) += 1;
            // Step along the axis whose boundary comes first, unless that axis
            // already reached the end cell (round-off at exact corners).
            let step_x = if key.ix == end.ix {
                false
            } else if key.iy == end.iy {
                true
            } else {
                tx <= ty
            };
            if step_x {
                key.ix += sx;
                tx += ddx;
            } else {
                key.iy += sy;
                ty += ddy;
            }
        }
    }

    /// Every crossed cell with its beam count, sorted by key.
    pub fn cells(&self) -> Vec<(CellKey, u32)> {
        let mut out: Vec<(CellKey, u32)> = self.counts.iter().map(|(&k, &c)| (k, c)).collect();
        out.sort_unstable_by_key(|(k, _)| *k);
        out
    }

    /// A dense image covering every crossed cell and every `occupied`
    /// map-frame point \[m\] (e.g. the NDT map's occupied cell centres): cells
    /// holding a point are [`OCCUPIED`], other crossed cells [`FREE`], the
    /// rest [`UNKNOWN`].
    ///
    /// Errors when nothing is known (no beam, no point), a point is not
    /// finite or beyond the lattice, or the image would have more than
    /// `max_cells` cells.
    pub fn raster(&self, occupied: &[[f64; 2]], max_cells: u64) -> Result<Raster> {
        check_points("occupied", occupied)?;
        let mut occ = Vec::with_capacity(occupied.len());
        for (index, p) in occupied.iter().enumerate() {
            occ.push(self.key("occupied", index, *p)?);
        }
        let keys = occ.iter().chain(self.counts.keys());
        let Some((lo, hi)) = keys.fold(None, |acc: Option<(CellKey, CellKey)>, k| {
            Some(match acc {
                None => (*k, *k),
                Some((lo, hi)) => (
                    CellKey {
                        ix: lo.ix.min(k.ix),
                        iy: lo.iy.min(k.iy),
                    },
                    CellKey {
                        ix: hi.ix.max(k.ix),
                        iy: hi.iy.max(k.iy),
                    },
                ),
            })
        }) else {
            return Err(NdtError::Empty {
                what: "free space and occupied",
            });
        };
        let width = (i64::from(hi.ix) - i64::from(lo.ix) + 1).unsigned_abs();
        let height = (i64::from(hi.iy) - i64::from(lo.iy) + 1).unsigned_abs();
        let size = width.saturating_mul(height);
        if size > max_cells {
            return Err(NdtError::TooLarge {
                what: "raster",
                size,
                limit: max_cells,
            });
        }
        let (w, h) = (width as usize, height as usize);
        let mut data = vec![UNKNOWN; w * h];
        let index = |k: &CellKey| {
            let c = (i64::from(k.ix) - i64::from(lo.ix)) as usize;
            let r = (i64::from(k.iy) - i64::from(lo.iy)) as usize;
            r * w + c
        };
        for k in self.counts.keys() {
            data[index(k)] = FREE;
        }
        for k in &occ {
            data[index(k)] = OCCUPIED;
        }
        Ok(Raster {
            origin: [
                f64::from(lo.ix) * self.resolution,
                f64::from(lo.iy) * self.resolution,
            ],
            resolution: self.resolution,
            width: w,
            height: h,
            data,
        })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn a_beam_frees_the_cells_before_its_hit() {
        let mut fs = FreeSpace::new(0.1).unwrap();
        // From (0.05, 0.05) along +x to 0.55: cells 0..4 free, cell 5 is the hit.
        fs.add_scan(&[[0.5, 0.0]], Pose2::new(0.05, 0.05, 0.0))
            .unwrap();
        let keys: Vec<(i32, i32, u32)> = fs.cells().iter().map(|(k, c)| (k.ix, k.iy, *c)).collect();
        assert_eq!(keys, (0..5).map(|i| (i, 0, 1)).collect::<Vec<_>>());
    }

    #[test]
    fn diagonal_beams_visit_a_connected_path() {
        let mut fs = FreeSpace::new(0.05).unwrap();
        let pts: Vec<[f64; 2]> = (0..36)
            .map(|i| {
                let a = f64::from(i) * 10f64.to_radians();
                [3.0 * a.cos(), 3.0 * a.sin()]
            })
            .collect();
        fs.add_scan(&pts, Pose2::new(0.01, -0.02, 0.3)).unwrap();
        // Each beam of 3 m crosses |Δix| + |Δiy| cells: between 60 and 85.
        let total: u32 = fs.cells().iter().map(|(_, c)| *c).sum();
        assert!((36 * 60..=36 * 85).contains(&total), "{total}");
        // No crossed cell is farther than the beams reach.
        for (k, _) in fs.cells() {
            let c = k.center(0.05);
            assert!(c.norm() < 3.1, "{k:?}");
        }
    }

    #[test]
    fn raster_marks_occupied_free_unknown() {
        let mut fs = FreeSpace::new(0.1).unwrap();
        fs.add_scan(&[[0.5, 0.0]], Pose2::new(0.05, 0.05, 0.0))
            .unwrap();
        let r = fs.raster(&[[0.55, 0.05], [0.15, 0.35]], 1000).unwrap();
        assert_eq!((r.width, r.height), (6, 4));
        assert_eq!(r.origin, [0.0, 0.0]);
        assert_eq!(&r.data[0..6], &[FREE, FREE, FREE, FREE, FREE, OCCUPIED]);
        assert_eq!(r.data[3 * 6 + 1], OCCUPIED);
        assert_eq!(r.data[6], UNKNOWN);
        assert!(matches!(
            fs.raster(&[[100.0, 0.0]], 1000),
            Err(NdtError::TooLarge { .. })
        ));
        let empty = FreeSpace::new(0.1).unwrap();
        assert!(matches!(empty.raster(&[], 10), Err(NdtError::Empty { .. })));
    }
}
