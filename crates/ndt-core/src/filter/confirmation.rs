//! §V-B(4) "Confirmation of detection result", step d: when a new scan is
//! stored, each beam is walked radially from the sensor to its hit; map cells
//! lying short of the hit were passed through, so they are free space now
//! and are removed. Cells of small objects are removed only in Area 1 (a beam
//! in Area 2 may slip past a thin object); cells of big objects everywhere,
//! which also removes objects that have moved.
//!
//! Three guards keep the walk from eating real surfaces (they are ours, not
//! the paper's):
//! - a cell counts as passed only when the beam passes within `pass_radius`
//!   of the mean of its points (a 2 cm cell is wider than a 1.5 cm stick;
//!   a beam through the cell beside the stick has not shown it is gone);
//! - the walk stops `margin` short of the hit, and more at grazing incidence
//!   ([`grazing_margin`]), where the beam runs along the very wall it hits;
//! - a small-object cell is removed only when one scan's beams pass its mean
//!   on both sides ([`cells_to_clear`]): the mean lies on the object's
//!   surface, so a beam that just misses the object from another side passes
//!   close to it on one side only.

use nalgebra::Vector2;
use rustc_hash::FxHashMap;

use crate::filter::areas::Area;
use crate::filter::observation::CellTable;
use crate::filter::walkmap::WalkMap;
use crate::filter::Beam;
use crate::key::CellKey;

/// How many points on each side of a hit estimate the surface direction.
const TANGENT_SPAN: usize = 3;

/// The along-beam margin \[m\] before the hit `cluster[i]` within which step d
/// removes nothing: `clear_margin / tan α` for a grazing angle `α < 45°`
/// between the beam and the surface, else `clear_margin`. The surface
/// direction is the chord between the points up to 3 beams either side in
/// the same cluster; a cluster of fewer than 3 points counts as facing the
/// sensor. Infinite when the beam runs along the surface.
pub fn grazing_margin(cluster: &[Beam], i: usize, sensor: Vector2<f64>, clear_margin: f64) -> f64 {
    let lo = i.saturating_sub(TANGENT_SPAN);
    let hi = (i + TANGENT_SPAN).min(cluster.len().saturating_sub(1));
    if hi < lo + 2 {
        return clear_margin;
    }
    let chord = cluster[hi].world - cluster[lo].world;
    let beam = cluster[i].world - sensor;
    let (cn, bn) = (chord.norm(), beam.norm());
    if cn == 0.0 || bn == 0.0 {
        return clear_margin;
    }
    let cos = (chord.dot(&beam) / (cn * bn)).abs();
    let sin = ((chord.x * beam.y - chord.y * beam.x) / (cn * bn)).abs();
    if sin >= cos {
        clear_margin
    } else if sin == 0.0 {
        f64::INFINITY
    } else {
        clear_margin * cos / sin
    }
}

/// What step d needs besides the beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearing {
    /// A cell is passed only if the beam passes within this distance \[m\] of
    /// the mean of its points.
    pub pass_radius: f64,
    /// Area 1 limit \[m\]: small-object cells farther away are kept.
    pub reliable_range: f64,
}

/// One beam passing a map cell (see [`passed_cells`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pass {
    /// The cell passed.
    pub key: CellKey,
    /// The cell belongs to a small object.
    pub small: bool,
    /// The side of the beam the cell's mean lies on (`true`: left, i.e.
    /// counter-clockwise).
    pub left: bool,
}

/// §V step d for one beam from `sensor` to `hit` (map frame \[m\]): appends to
/// `out` the cells of `map` the beam passed through short of its hit — every
/// cell the walk crosses up to `margin` \[m\] before the hit whose point mean
/// lies within `pass_radius` of the beam and more than `margin` short of the
/// hit — except cells of small objects (per `table`) beyond the reliable
/// range.
pub fn passed_cells(
    map: &mut WalkMap<'_>,
    table: &CellTable,
    sensor: Vector2<f64>,
    hit: Vector2<f64>,
    margin: f64,
    clearing: Clearing,
    out: &mut Vec<Pass>,
) {
    let ray = hit - sensor;
    let range = ray.norm();
    if range.partial_cmp(&margin) != Some(std::cmp::Ordering::Greater) {
        return;
    }
    let dir = ray / range;
    let reach = range - margin;
    let grid = map.grid();
    let cell_size = grid.cell_size();
    // The walk crosses the blocks the occupancy shows empty without visiting
    // them; of the cells it visits, the occupied ones are looked up.
    map.walk(sensor, sensor + dir * reach, |key, occupied| {
        if !occupied {
            return true;
        }
        let Some(stats) = grid.stats(key) else {
            return true;
        };
        if stats.count == 0 {
            return true;
        }
        let mean = key.center(cell_size) + stats.sum / stats.points();
        let rel = mean - sensor;
        let along = rel.dot(&dir);
        let side = dir.x * rel.y - dir.y * rel.x;
        if along <= 0.0 || along >= reach || side.abs() > clearing.pass_radius {
            return true;
        }
        let small = table.get(&key).is_some_and(|c| c.is_small());
        if !small || Area::of(rel.norm(), clearing.reliable_range) == Area::Reliable {
            out.push(Pass {
                key,
                small,
                left: side > 0.0,
            });
        }
        true
    });
}

/// §V step d for a whole scan: the cells to remove given every beam's
/// passes. A big-object cell goes when any beam passed it; a small-object
/// cell only when beams passed its mean on both sides. Sorted, no repeats.
pub fn cells_to_clear(passes: &[Pass]) -> Vec<CellKey> {
    let mut sides: FxHashMap<CellKey, (bool, bool, bool)> = FxHashMap::default();
    for p in passes {
        let e = sides.entry(p.key).or_insert((p.small, false, false));
        if p.left {
            e.1 = true;
        } else {
            e.2 = true;
        }
    }
    super::sorted_keys(sides, |_, (small, left, right)| !small || (*left && *right))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::filter::observation::CellInfo;
    use crate::{NdtGrid, Pose2};

    fn setup() -> (NdtGrid, CellTable) {
        let mut grid = NdtGrid::new(0.02).unwrap();
        let mut table = CellTable::default();
        // A big cell at 0.3 m, a small one at 0.4 m (Area 1) and a small one
        // at 0.8 m (Area 2), all on the x axis.
        for (x, small) in [(0.301, false), (0.401, true), (0.801, true)] {
            let keys = grid.insert(&[[x, 0.001]], Pose2::identity()).unwrap();
            let info = table.entry(keys[0]).or_insert(CellInfo::new(1));
            info.observe(1, small, false);
        }
        (grid, table)
    }

    #[test]
    fn d_removes_passed_cells_but_small_ones_only_in_area1() {
        let (grid, table) = setup();
        let clearing = Clearing {
            pass_radius: 0.005,
            reliable_range: 0.5,
        };
        let mut out = Vec::new();
        passed_cells(
            &mut WalkMap::new(&grid),
            &table,
            Vector2::zeros(),
            Vector2::new(2.0, 0.0),
            0.04,
            clearing,
            &mut out,
        );
        let key = |x: f64| CellKey::of(Vector2::new(x, 0.001), 50.0).unwrap();
        let keys: Vec<CellKey> = out.iter().map(|p| p.key).collect();
        assert_eq!(keys, vec![key(0.301), key(0.401)]);
        assert_eq!(
            out.iter().map(|p| (p.small, p.left)).collect::<Vec<_>>(),
            vec![(false, true), (true, true)]
        );
        // One pass clears the big cell; the small one needs both sides.
        assert_eq!(cells_to_clear(&out), vec![key(0.301)]);
        passed_cells(
            &mut WalkMap::new(&grid),
            &table,
            Vector2::new(0.0, 0.004),
            Vector2::new(2.0, 0.004),
            0.04,
            clearing,
            &mut out,
        );
        assert_eq!(cells_to_clear(&out), vec![key(0.301), key(0.401)]);
        // From farther back the small cell at 0.4 m is in Area 2 too.
        out.clear();
        passed_cells(
            &mut WalkMap::new(&grid),
            &table,
            Vector2::new(-0.2, 0.0),
            Vector2::new(2.0, 0.0),
            0.04,
            clearing,
            &mut out,
        );
        assert_eq!(
            out.iter().map(|p| p.key).collect::<Vec<_>>(),
            vec![key(0.301)]
        );
    }

    #[test]
    fn d_keeps_cells_near_the_hit_and_beside_the_beam() {
        let (grid, table) = setup();
        let clearing = Clearing {
            pass_radius: 0.005,
            reliable_range: 0.5,
        };
        let mut out = Vec::new();
        // The hit 3 cm behind the big cell: within the 4 cm margin.
        passed_cells(
            &mut WalkMap::new(&grid),
            &table,
            Vector2::zeros(),
            Vector2::new(0.331, 0.001),
            0.04,
            clearing,
            &mut out,
        );
        assert!(out.is_empty());
        // A beam crossing the cell 8 mm beside the mean of its points.
        passed_cells(
            &mut WalkMap::new(&grid),
            &table,
            Vector2::new(0.0, 0.009),
            Vector2::new(2.0, 0.009),
            0.04,
            clearing,
            &mut out,
        );
        assert!(out.is_empty());
    }

    #[test]
    fn grazing_margin_grows_as_the_beam_flattens() {
        // A wall along y = 1 seen from the origin.
        let wall: Vec<Beam> = (0..9)
            .map(|i| {
                let x = 0.5 + 0.01 * f64::from(i);
                let r = (x * x + 1.0f64).sqrt();
                Beam::new(i as usize, r, (1.0f64).atan2(x), Pose2::identity())
            })
            .collect();
        let m = grazing_margin(&wall, 4, Vector2::zeros(), 0.03);
        // The beam to (0.54, 1) meets the wall at atan(1/0.54) = 61.6°.
        assert!((m - 0.03).abs() < 1e-12);
        let far: Vec<Beam> = (0..9)
            .map(|i| {
                let x = 4.0 + 0.05 * f64::from(i);
                let r = (x * x + 0.04f64).sqrt();
                Beam::new(i as usize, r, (0.2f64).atan2(x), Pose2::new(0.0, 0.8, 0.0))
            })
            .collect();
        // Sensor at (0, 0.8), wall along y = 1 at x = 4.2: tan α = 0.2/4.2.
        let g = grazing_margin(&far, 4, Vector2::new(0.0, 0.8), 0.03);
        assert!((g - 0.03 * 4.2 / 0.2).abs() < 1e-9, "{g}");
        assert_eq!(grazing_margin(&far[..2], 0, Vector2::zeros(), 0.03), 0.03);
    }
}
