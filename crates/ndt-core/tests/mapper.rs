//! The §V mapper end to end: failed calls change nothing, the unfiltered map
//! is plain insertion, and a moved object leaves the map (step d).

mod common;

use ndt_core::{points_from_ranges, Mapper, MapperOptions, NdtError, NdtGrid, Pose2};

/// Ranges and angles of a scan given as scan-frame points (beam order kept).
fn polar(points: &[[f64; 2]]) -> (Vec<f64>, Vec<f64>) {
    points
        .iter()
        .map(|p| (p[0].hypot(p[1]), p[1].atan2(p[0])))
        .unzip()
}

fn poses() -> Vec<Pose2> {
    (0..12)
        .map(|i| {
            let t = f64::from(i);
            Pose2::new(-0.5 + 0.08 * t, -0.6 + 0.03 * t, 0.1 * t)
        })
        .collect()
}

#[test]
fn a_failed_insert_changes_nothing() {
    let walls = common::room();
    let mut mapper = Mapper::new(0.02, MapperOptions::default()).unwrap();
    for (i, &p) in poses().iter().take(5).enumerate() {
        let (r, a) = polar(&common::urg_scan(&walls, p, 0.005, i as u64));
        mapper.insert_scan(&r, &a, p).unwrap();
    }
    let before = (
        mapper.grid().cells(),
        mapper.removal_counts(),
        mapper.filter().scans(),
        mapper.small_objects(),
    );
    let (mut r, a) = polar(&common::urg_scan(&walls, poses()[5], 0.005, 5));
    r[100] = 1e300;
    let err = mapper.insert_scan(&r, &a, poses()[5]).unwrap_err();
    assert!(matches!(
        err,
        NdtError::CellIndexOverflow {
            what: "ranges",
            index: 100,
            ..
        }
    ));
    let mut short = a.clone();
    short.pop();
    // A NaN pose (with a valid scan, the 1e300 range dropped).
    assert!(matches!(
        mapper.insert_scan(&r[..100], &a[..100], Pose2::new(f64::NAN, 0.0, 0.0)),
        Err(NdtError::NonFinite { what: "pose", .. })
    ));
    assert!(matches!(
        mapper.insert_scan(&r, &short, poses()[5]),
        Err(NdtError::LengthMismatch { what: "angles", .. })
    ));
    let after = (
        mapper.grid().cells(),
        mapper.removal_counts(),
        mapper.filter().scans(),
        mapper.small_objects(),
    );
    assert_eq!(before, after);
}

#[test]
fn unfiltered_is_plain_insertion() {
    let walls = common::room();
    let mut mapper = Mapper::new(0.02, MapperOptions::unfiltered()).unwrap();
    let mut grid = NdtGrid::new(0.02).unwrap();
    for (i, &p) in poses().iter().enumerate() {
        let (mut r, a) = polar(&common::urg_scan(&walls, p, 0.005, i as u64));
        r[3] = 0.0;
        r[7] = f64::NAN;
        mapper.insert_scan(&r, &a, p).unwrap();
        grid.insert(&points_from_ranges(&r, &a, 0.0, f64::INFINITY).unwrap(), p)
            .unwrap();
    }
    assert_eq!(mapper.grid().cells(), grid.cells());
    assert_eq!(mapper.removal_counts(), Default::default());
}

#[test]
fn a_removed_box_leaves_the_map() {
    let mut walls = common::room();
    let room_only = walls.clone();
    // A 0.4 m box in the middle of the room, seen by the first six scans.
    let (x0, y0, x1, y1) = (-0.3, 0.3, 0.1, 0.7);
    walls.extend([
        ([x0, y0], [x1, y0]),
        ([x1, y0], [x1, y1]),
        ([x1, y1], [x0, y1]),
        ([x0, y1], [x0, y0]),
    ]);
    let on_box = |m: &Mapper| {
        m.occupied_cells()
            .iter()
            .filter(|k| {
                let c = k.center(0.02);
                c.x > x0 - 0.02 && c.x < x1 + 0.02 && c.y > y0 - 0.02 && c.y < y1 + 0.02
            })
            .count()
    };
    for (radial, expect_gone) in [(true, true), (false, false)] {
        let options = MapperOptions {
            radial_confirmation: radial,
            ..MapperOptions::default()
        };
        let mut mapper = Mapper::new(0.02, options).unwrap();
        for (i, &p) in poses().iter().enumerate() {
            let world = if i < 6 { &walls } else { &room_only };
            let (r, a) = polar(&common::urg_scan(world, p, 0.003, i as u64));
            mapper.insert_scan(&r, &a, p).unwrap();
            if i == 5 {
                assert!(on_box(&mapper) > 20);
            }
        }
        assert_eq!(on_box(&mapper) == 0, expect_gone, "radial = {radial}");
        if radial {
            assert!(mapper.removal_counts().confirmation_cells > 20);
        }
    }
}
