//! Saving and loading (`ndt_core::persist`): exact round trips, a loaded
//! mapper that goes on exactly as the saved one, exact error messages,
//! atomic writes, and corruption (every truncation, seeded byte flips,
//! arbitrary bytes) that is always rejected and never panics.
//!
//! The corruption tests print how many cases they ran (`--nocapture`).

mod common;

use std::path::{Path, PathBuf};

use ndt_core::persist::header::{checksum, seal, FileKind};
use ndt_core::persist::wire::{self, GridV1, MapperV1};
use ndt_core::persist::{HEADER_LEN, VERSION};
use ndt_core::{Mapper, MapperOptions, MatchOptions, NdtError, NdtGrid, Pose2};
use proptest::prelude::*;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// Ranges and angles of a scan given as scan-frame points (beam order kept).
fn polar(points: &[[f64; 2]]) -> (Vec<f64>, Vec<f64>) {
    points
        .iter()
        .map(|p| (p[0].hypot(p[1]), p[1].atan2(p[0])))
        .unzip()
}

fn pose(i: usize) -> Pose2 {
    let t = i as f64;
    Pose2::new(-0.5 + 0.08 * t, -0.6 + 0.03 * t, 0.1 * t)
}

/// Inserts scans `range` of the room walk into `mapper`.
fn feed(mapper: &mut Mapper, range: std::ops::Range<usize>) {
    let walls = common::room();
    for i in range {
        let (r, a) = polar(&common::urg_scan(&walls, pose(i), 0.005, i as u64));
        mapper.insert_scan(&r, &a, pose(i)).unwrap();
    }
}

/// A mapper of `cell` m cells after `scans` scans of the room.
fn mapper(cell: f64, scans: usize) -> Mapper {
    let mut m = Mapper::new(cell, MapperOptions::default()).unwrap();
    feed(&mut m, 0..scans);
    m
}

/// A grid of a few hundred cells (5 cm cells, 2 scans).
fn small_grid() -> NdtGrid {
    mapper(0.05, 2).into_parts().0
}

/// A fresh empty directory under the target directory.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("persist-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `bytes` with the version field set to `version` and the checksum fixed.
fn with_version(bytes: &[u8], version: u32) -> Vec<u8> {
    let mut out = bytes.to_vec();
    out[12..16].copy_from_slice(&version.to_le_bytes());
    let crc = checksum(&out[..24], &out[HEADER_LEN..]);
    out[24..28].copy_from_slice(&crc.to_le_bytes());
    out
}

// --- round trips -------------------------------------------------------------

#[test]
fn grid_round_trip_is_bit_identical_and_matches_the_same() {
    let grid = mapper(0.02, 4).into_parts().0;
    let bytes = grid.to_bytes().unwrap();
    let back = NdtGrid::from_bytes(&bytes).unwrap();
    assert_eq!(back.cell_states(), grid.cell_states());
    assert_eq!((back.cell_size(), back.levels()), (0.02, grid.levels()));
    assert_eq!(back.to_bytes().unwrap(), bytes);
    for l in 0..grid.levels() {
        let (a, b) = (grid.level(l).unwrap(), back.level(l).unwrap());
        assert_eq!(a.cells(), b.cells(), "level {l}");
    }
    let walls = common::room();
    let opts = MatchOptions::default();
    for i in 0..3 {
        let pts = common::urg_scan(&walls, pose(4 + i), 0.005, 100 + i as u64);
        let guess = Pose2::new(
            pose(4 + i).x + 0.03,
            pose(4 + i).y - 0.02,
            pose(4 + i).theta,
        );
        let a = grid.match_scan(&pts, guess, &opts).unwrap();
        let b = back.match_scan(&pts, guess, &opts).unwrap();
        assert_eq!(a, b);
    }
}

#[test]
fn levels_and_empty_grids_round_trip() {
    let mut grid = NdtGrid::with_levels(0.1, 3).unwrap();
    let back = NdtGrid::from_bytes(&grid.to_bytes().unwrap()).unwrap();
    assert_eq!((back.levels(), back.len(), back.cell_size()), (3, 0, 0.1));
    grid.insert(&[[1.0, 2.0], [-3.0, 4.5]], Pose2::new(0.1, 0.2, 0.3))
        .unwrap();
    let back = NdtGrid::from_bytes(&grid.to_bytes().unwrap()).unwrap();
    assert_eq!(back.levels(), 3);
    assert_eq!(back.cell_states(), grid.cell_states());
}

/// Everything observable of a mapper, and its bytes (its whole state).
fn snapshot(m: &Mapper) -> impl PartialEq + std::fmt::Debug {
    (
        m.grid().cell_states(),
        m.occupied_cells(),
        m.removal_counts(),
        m.filter().scans(),
        m.small_objects(),
        m.filter().cell_records(),
        m.to_bytes().unwrap(),
    )
}

#[test]
fn a_loaded_mapper_goes_on_exactly_as_the_saved_one() {
    // 7 scans: the last periodic check was at scan 6, so the table holds
    // cells that the next check judges.
    let mut original = mapper(0.02, 7);
    let bytes = original.to_bytes().unwrap();
    let mut loaded = Mapper::from_bytes(&bytes).unwrap();
    assert_eq!(snapshot(&loaded), snapshot(&original));
    feed(&mut original, 7..12);
    feed(&mut loaded, 7..12);
    assert_eq!(snapshot(&loaded), snapshot(&original));
    assert!(original
        .removal_counts()
        .entries()
        .iter()
        .any(|(_, v)| *v > 0));
    assert_eq!(original.filter().scans(), 12);
}

#[test]
fn records_that_outlive_their_cells_are_kept() {
    // Cells removed from the map directly keep their records until the
    // next check; the loaded mapper must keep them too.
    let mut original = mapper(0.02, 4);
    let gone: Vec<_> = original.occupied_cells().into_iter().step_by(5).collect();
    assert!(original.remove_cells(&gone) > 0);
    let mut loaded = Mapper::from_bytes(&original.to_bytes().unwrap()).unwrap();
    assert!(loaded.filter().cell_records().len() > loaded.grid().len());
    feed(&mut original, 4..8);
    feed(&mut loaded, 4..8);
    assert_eq!(snapshot(&loaded), snapshot(&original));
}

#[test]
fn files_round_trip_and_replace_the_old_file_whole() {
    let dir = scratch("files");
    let path = dir.join("map.ndtgrid");
    // An older, longer file of another kind is replaced whole.
    let big = mapper(0.02, 6);
    big.save(&path).unwrap();
    let grid = small_grid();
    grid.save(&path).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), grid.to_bytes().unwrap());
    assert_eq!(
        NdtGrid::load(&path).unwrap().cell_states(),
        grid.cell_states()
    );
    assert_eq!(listing(&dir), ["map.ndtgrid"]);
    big.save(dir.join("mapper.ndtgrid")).unwrap();
    let back = Mapper::load(dir.join("mapper.ndtgrid")).unwrap();
    assert_eq!(snapshot(&back), snapshot(&big));
    assert_eq!(listing(&dir), ["map.ndtgrid", "mapper.ndtgrid"]);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // Not the 0o600 of a temporary file: the usual 0o666 less the umask.
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o044, 0o044, "mode {mode:o}");
    }
}

// --- the layout of version 1 (frozen: a change here needs a new version) ------

#[test]
fn version_1_layout_is_frozen() {
    use nalgebra::{Matrix2, Vector2};
    let stats = ndt_core::CellStats {
        count: 3,
        sum: Vector2::new(0.125, -0.25),
        scatter: Matrix2::new(0.5, 0.0625, 0.0625, 1.0),
    };
    let key = ndt_core::CellKey { ix: -3, iy: 7 };
    let grid = NdtGrid::from_cell_states(0.5, &[(key, stats)]).unwrap();
    // The payload, field by field (postcard: f64 as 8 bytes little-endian,
    // integers as varints, i32 zigzag-encoded, sequences prefixed by length).
    let mut payload = 0.5f64.to_le_bytes().to_vec(); // cell size
    payload.push(6); // levels
    payload.push(1); // one cell
    payload.extend_from_slice(&[5, 14]); // ix = -3, iy = 7 (zigzag)
    payload.push(3); // count
    for v in [0.125f64, -0.25, 0.5, 0.0625, 0.0625, 1.0] {
        payload.extend_from_slice(&v.to_le_bytes()); // sum, then scatter row-major
    }
    let mut expected = b"NDTGRID\0GRID".to_vec();
    expected.extend_from_slice(&1u32.to_le_bytes());
    expected.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&expected);
    crc.update(&payload);
    expected.extend_from_slice(&crc.finalize().to_le_bytes());
    expected.extend_from_slice(&payload);
    assert_eq!(grid.to_bytes().unwrap(), expected);
    // A new mapper with the default options, byte for byte.
    let mapper = Mapper::new(0.5, MapperOptions::default()).unwrap();
    let hex: String = mapper
        .to_bytes()
        .unwrap()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(
        hex,
        "4e445447524944004d41505201000000760000000000000009b8c83e000000000000e03f0600010101\
         0101010000000000000000000000000000f07f000000000000e03f9a9999999999a93f0000000000000040\
         9a9999999999a93f00000000000000009a9999999999b93f030201b81e85eb51b89e3fb81e85eb51b88e3f\
         7b14ae47e17a743f0000000000000000000000"
    );
}

// --- errors ------------------------------------------------------------------

fn message<T>(r: Result<T, NdtError>) -> String {
    match r {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn format_errors_have_exact_messages() {
    let grid = small_grid();
    let bytes = grid.to_bytes().unwrap();
    let n = bytes.len();
    assert_eq!(
        message(NdtGrid::from_bytes(b"PK\x03\x04 a zip file, not a map")),
        r#"not an ndtgrid file (it does not start with the magic bytes "NDTGRID\0")"#
    );
    assert_eq!(
        message(Mapper::from_bytes(&bytes)),
        "wrong kind of ndtgrid file: expected a mapper file, got a grid file"
    );
    let m = mapper(0.05, 1).to_bytes().unwrap();
    assert_eq!(
        message(NdtGrid::from_bytes(&m)),
        "wrong kind of ndtgrid file: expected a grid file, got a mapper file"
    );
    let mut odd = bytes.clone();
    odd[8..12].copy_from_slice(b"ODOM");
    assert_eq!(
        message(NdtGrid::from_bytes(&odd)),
        "wrong kind of ndtgrid file: expected a grid file, got an unknown kind tagged ODOM"
    );
    assert_eq!(
        message(NdtGrid::from_bytes(&with_version(&bytes, VERSION + 1))),
        "unsupported ndtgrid file version 2: this build reads version 1"
    );
    assert_eq!(
        message(NdtGrid::from_bytes(&bytes[..n - 1])),
        format!("truncated ndtgrid file: expected {n} bytes, got {}", n - 1)
    );
    assert_eq!(
        message(NdtGrid::from_bytes(&bytes[..20])),
        "truncated ndtgrid file: expected 28 bytes, got 20"
    );
    assert_eq!(
        message(NdtGrid::from_bytes(&[])),
        "truncated ndtgrid file: expected 28 bytes, got 0"
    );
    let mut long = bytes.clone();
    long.extend_from_slice(b"xyz");
    assert_eq!(
        message(NdtGrid::from_bytes(&long)),
        format!(
            "ndtgrid file has 3 unexpected bytes after its payload: expected {n} bytes, got {}",
            n + 3
        )
    );
    let mut flipped = bytes.clone();
    flipped[n / 2] ^= 0x10;
    let stored = u32::from_le_bytes(bytes[24..28].try_into().unwrap());
    let computed = checksum(&flipped[..24], &flipped[HEADER_LEN..]);
    assert_eq!(
        message(NdtGrid::from_bytes(&flipped)),
        format!(
            "corrupt ndtgrid file: checksum mismatch (stored {stored:#010x}, computed {computed:#010x})"
        )
    );
}

#[test]
fn content_errors_have_exact_messages() {
    // A faulty writer: the checksum is right, the content is not.
    let grid = small_grid();
    assert_eq!(
        message(NdtGrid::from_bytes(&seal(FileKind::Grid, &[1, 2, 3]))),
        "corrupt ndtgrid file: cannot decode the payload: Hit the end of buffer, expected more data"
    );
    let mut payload = wire::encode(&GridV1::of(&grid)).unwrap();
    payload.push(0);
    assert_eq!(
        message(NdtGrid::from_bytes(&seal(FileKind::Grid, &payload))),
        "corrupt ndtgrid file: cannot decode the payload: 1 bytes left over after the payload"
    );
    let mut w = GridV1::of(&grid);
    w.cells[7].count = 0;
    let bytes = seal(FileKind::Grid, &wire::encode(&w).unwrap());
    assert_eq!(
        message(NdtGrid::from_bytes(&bytes)),
        "cells: cell 7 has a count of 0 (empty cells are not stored)"
    );
    let mut w = GridV1::of(&grid);
    w.cells[3].sum[1] = f64::NAN;
    let bytes = seal(FileKind::Grid, &wire::encode(&w).unwrap());
    assert_eq!(
        message(NdtGrid::from_bytes(&bytes)),
        "cells: cell 3 has a non-finite sum"
    );
    let mut w = GridV1::of(&grid);
    w.levels = 13;
    let bytes = seal(FileKind::Grid, &wire::encode(&w).unwrap());
    assert_eq!(
        message(NdtGrid::from_bytes(&bytes)),
        "levels: expected between 1 and 12 pyramid levels, got 13"
    );
    let m = mapper(0.05, 2);
    let base = MapperV1 {
        grid: GridV1::of(m.grid()),
        filter: wire::FilterV1::of(m.filter()),
    };
    let seal_mapper = |w: &MapperV1| seal(FileKind::Mapper, &wire::encode(w).unwrap());
    let mut w = base.clone();
    w.filter.options.cluster_gap = -1.0;
    assert_eq!(
        message(Mapper::from_bytes(&seal_mapper(&w))),
        "cluster_gap: expected a finite length >= 0 m, got -1"
    );
    let mut w = base.clone();
    w.filter.records[4].last_seen = 3;
    assert_eq!(
        message(Mapper::from_bytes(&seal_mapper(&w))),
        "filter: record 4 was seen in a scan after the last scan"
    );
    let mut w = base.clone();
    w.filter.records[2].small_observations = w.filter.records[2].observations + 1;
    assert_eq!(
        message(Mapper::from_bytes(&seal_mapper(&w))),
        "filter: record 2 has more small-cluster observations than observations"
    );
    let mut w = base.clone();
    w.filter.records[1] = w.filter.records[0];
    assert_eq!(
        message(Mapper::from_bytes(&seal_mapper(&w))),
        "filter: record 1 repeats the index of an earlier record"
    );
    let mut w = base.clone();
    w.filter.counts.area1_cells = u64::MAX;
    assert_eq!(
        message(Mapper::from_bytes(&seal_mapper(&w))),
        format!(
            "area1_cells: {} is beyond the limit of {} of a saved map",
            u64::MAX,
            1u64 << 62
        )
    );
    // The untouched state loads.
    assert!(Mapper::from_bytes(&seal_mapper(&base)).is_ok());
}

#[test]
fn file_errors_name_the_file() {
    let dir = scratch("errors");
    let missing = dir.join("missing.ndtgrid");
    let err = NdtGrid::load(&missing).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "{}: cannot read the file: No such file or directory",
            missing.display()
        )
    );
    assert!(matches!(err, NdtError::Io { errno: Some(2), .. }));
    let err = Mapper::load(&dir).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!("{}: cannot read the file: Is a directory", dir.display())
    );
    let bad = dir.join("bad.ndtgrid");
    std::fs::write(&bad, &small_grid().to_bytes().unwrap()[..100]).unwrap();
    let err = NdtGrid::load(&bad).unwrap_err();
    assert!(matches!(err, NdtError::InFile { .. }));
    assert!(err.to_string().starts_with(&format!(
        "{}: truncated ndtgrid file: expected ",
        bad.display()
    )));
    let err = Mapper::load(&bad).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "{}: wrong kind of ndtgrid file: expected a mapper file, got a grid file",
            bad.display()
        )
    );
}

#[test]
fn failed_saves_leave_no_temporary_file_and_the_old_file_intact() {
    let dir = scratch("failed");
    let grid = small_grid();
    // The parent does not exist.
    let orphan = dir.join("no-such-dir").join("map.ndtgrid");
    let err = grid.save(&orphan).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "{}: cannot create a temporary file beside it: No such file or directory",
            orphan.display()
        )
    );
    // The target is a (non-empty) directory: the rename fails.
    let target = dir.join("taken");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("keep"), b"keep").unwrap();
    let err = grid.save(&target).unwrap_err();
    assert!(
        err.to_string()
            .starts_with(&format!("{}: cannot replace the file: ", target.display())),
        "{err}"
    );
    assert_eq!(listing(&target), ["keep"]);
    assert_eq!(listing(&dir), ["taken"]);
    // A read-only directory (not enforced for root: then the save succeeds).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let ro = dir.join("ro");
        std::fs::create_dir(&ro).unwrap();
        let path = ro.join("map.ndtgrid");
        let old = mapper(0.05, 1).to_bytes().unwrap();
        std::fs::write(&path, &old).unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        let enforced = std::fs::write(ro.join("probe"), b"").is_err();
        let result = grid.save(&path);
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
        if enforced {
            let err = result.unwrap_err();
            assert!(
                matches!(
                    err,
                    NdtError::Io {
                        errno: Some(13),
                        ..
                    }
                ),
                "{err}"
            );
            assert_eq!(std::fs::read(&path).unwrap(), old);
            assert_eq!(listing(&ro), ["map.ndtgrid"]);
        } else {
            eprintln!("read-only directory not enforced (running as root): skipped");
        }
    }
}

// --- corruption ----------------------------------------------------------------

/// The error's variant name, for tallies.
fn variant(e: &NdtError) -> &'static str {
    match e {
        NdtError::NotNdtFile => "not an ndtgrid file",
        NdtError::WrongKind { .. } => "wrong kind",
        NdtError::UnsupportedVersion { .. } => "unsupported version",
        NdtError::Truncated { .. } => "truncated",
        NdtError::TrailingBytes { .. } => "trailing bytes",
        NdtError::ChecksumMismatch { .. } => "checksum mismatch",
        NdtError::Decode { .. } => "decode",
        NdtError::InvalidCell { .. } => "invalid cell",
        NdtError::InvalidRecord { .. } => "invalid record",
        NdtError::InvalidOption { .. } => "invalid option",
        NdtError::InvalidCounter { .. } => "invalid counter",
        _ => "other",
    }
}

fn tally(
    counts: &mut std::collections::BTreeMap<&'static str, usize>,
    r: &Result<Vec<u8>, NdtError>,
) {
    let key = match r {
        Ok(_) => "loaded",
        Err(e) => variant(e),
    };
    *counts.entry(key).or_default() += 1;
}

/// Loads `bytes` as a grid or a mapper file: the loaded map's bytes.
fn load_any(kind: FileKind, bytes: &[u8]) -> Result<Vec<u8>, NdtError> {
    match kind {
        FileKind::Grid => NdtGrid::from_bytes(bytes)?.to_bytes(),
        FileKind::Mapper => Mapper::from_bytes(bytes)?.to_bytes(),
    }
}

fn saved_maps() -> Vec<(FileKind, Vec<u8>)> {
    let grid = small_grid();
    let m = mapper(0.05, 4);
    assert!((200..1000).contains(&grid.len()), "{} cells", grid.len());
    assert!(
        (200..2000).contains(&m.grid().len()),
        "{} cells",
        m.grid().len()
    );
    vec![
        (FileKind::Grid, grid.to_bytes().unwrap()),
        (FileKind::Mapper, m.to_bytes().unwrap()),
    ]
}

#[test]
fn every_truncation_is_rejected() {
    for (kind, bytes) in saved_maps() {
        let mut counts = Default::default();
        for len in 0..bytes.len() {
            let r = load_any(kind, &bytes[..len]);
            assert!(r.is_err(), "{kind:?}: prefix of {len} bytes loaded");
            tally(&mut counts, &r);
        }
        eprintln!(
            "{kind:?} file of {} bytes: {} truncations, all rejected: {counts:?}",
            bytes.len(),
            bytes.len()
        );
    }
}

/// `bytes` with 1–4 bytes at random places xor-ed with random non-zero masks.
fn flip(rng: &mut StdRng, bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        let at = rng.random_range(0..out.len());
        out[at] ^= rng.random_range(1..=255u8);
    }
    out
}

#[test]
fn random_byte_flips_are_rejected_or_load_the_same_map() {
    const FLIPS: usize = 10_000;
    let mut rng = StdRng::seed_from_u64(0x5eed);
    for (kind, bytes) in saved_maps() {
        let mut counts = Default::default();
        for _ in 0..FLIPS {
            let bad = flip(&mut rng, &bytes);
            let r = load_any(kind, &bad);
            if let Ok(loaded) = &r {
                // Only a flip that changes nothing may load (xor masks are
                // non-zero, but two flips can hit one byte and cancel).
                assert_eq!(
                    loaded, &bytes,
                    "{kind:?}: a corrupt file loaded a different map"
                );
                assert_eq!(bad, bytes);
            }
            tally(&mut counts, &r);
        }
        eprintln!("{kind:?} file: {FLIPS} seeded flips of 1-4 bytes: {counts:?}");
    }
}

#[test]
fn flips_behind_a_recomputed_checksum_never_panic() {
    // A faulty writer with a right checksum: the decoder and the validation
    // see the corrupt payload. Whatever loads is a valid map that can be
    // saved again, matched against and fed.
    const FLIPS: usize = 1_000;
    let mut rng = StdRng::seed_from_u64(0xfa17);
    let walls = common::room();
    let pts = common::urg_scan(&walls, pose(5), 0.005, 5);
    let (r, a) = polar(&pts);
    for (kind, bytes) in saved_maps() {
        let payload = &bytes[HEADER_LEN..];
        let mut counts = Default::default();
        for i in 0..FLIPS {
            let bad = seal(kind, &flip(&mut rng, payload));
            let res = load_any(kind, &bad);
            tally(&mut counts, &res);
            if let Ok(again) = res {
                assert_eq!(load_any(kind, &again).unwrap(), again);
                if i % 25 == 0 {
                    match kind {
                        FileKind::Grid => {
                            let g = NdtGrid::from_bytes(&bad).unwrap();
                            let _ = g.match_scan(&pts, pose(5), &MatchOptions::default());
                        }
                        FileKind::Mapper => {
                            let mut m = Mapper::from_bytes(&bad).unwrap();
                            let _ = m.insert_scan(&r, &a, pose(5));
                        }
                    }
                }
            }
        }
        eprintln!("{kind:?} payload: {FLIPS} flips with a recomputed checksum: {counts:?}");
    }
}

proptest! {
    // Cases: proptest's default (256), or PROPTEST_CASES. No regression file
    // (proptest cannot place one beside an integration test).
    #![proptest_config(ProptestConfig {
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        prop_assert!(NdtGrid::from_bytes(&bytes).is_err());
        prop_assert!(Mapper::from_bytes(&bytes).is_err());
    }

    #[test]
    fn arbitrary_bytes_after_the_magic_never_panic(
        tail in proptest::collection::vec(any::<u8>(), 0..512),
    ) {
        let mut bytes = ndt_core::persist::MAGIC.to_vec();
        bytes.extend_from_slice(&tail);
        prop_assert!(NdtGrid::from_bytes(&bytes).is_err());
        prop_assert!(Mapper::from_bytes(&bytes).is_err());
    }

    #[test]
    fn arbitrary_payloads_with_a_right_checksum_never_panic(
        payload in proptest::collection::vec(any::<u8>(), 0..512),
    ) {
        // Mostly decode errors; whatever loads must save back the same.
        if let Ok(g) = NdtGrid::from_bytes(&seal(FileKind::Grid, &payload)) {
            prop_assert!(g.to_bytes().is_ok());
        }
        if let Ok(m) = Mapper::from_bytes(&seal(FileKind::Mapper, &payload)) {
            prop_assert!(m.to_bytes().is_ok());
        }
    }

    #[test]
    fn arbitrary_well_formed_states_never_panic(
        cell_size in prop_oneof![9 => Just(0.05), 1 => any::<f64>()],
        levels in prop_oneof![9 => 1u32..=12, 1 => any::<u32>()],
        cells in proptest::collection::vec(cell_strategy(), 0..12),
        records in proptest::collection::vec(record_strategy(), 0..6),
        scans in prop_oneof![9 => 20u64..60, 1 => any::<u64>()],
        counter in prop_oneof![9 => 0u64..40, 1 => any::<u64>()],
        gap in prop_oneof![9 => Just(0.05), 1 => any::<f64>()],
        interval in 0u32..5,
    ) {
        // Well-formed encodings of arbitrary states (right checksum, every
        // field decodable): only the validation stands between them and the
        // map. Whatever loads must save back the same and take a scan (with
        // cells of at least 1 mm: a legal 1e-8 m cell makes each beam's ray
        // walk cross 1e8 cells, as it would in a new mapper).
        let usable = cell_size >= 1e-3;
        let grid = GridV1 { cell_size, levels, cells };
        let fresh = Mapper::new(0.05, MapperOptions::default()).unwrap();
        let mut filter = wire::FilterV1::of(fresh.filter());
        filter.records = records;
        filter.scans = scans;
        filter.counts.confirmation_cells = counter;
        filter.options.cluster_gap = gap;
        filter.options.check_interval = interval;
        let state = MapperV1 { grid: grid.clone(), filter };
        let bytes = seal(FileKind::Mapper, &wire::encode(&state).unwrap());
        if let Ok(mut m) = Mapper::from_bytes(&bytes) {
            let again = m.to_bytes().unwrap();
            prop_assert_eq!(Mapper::from_bytes(&again).unwrap().to_bytes().unwrap(), again);
            if usable {
                let angles: Vec<f64> = (0..60).map(|i| f64::from(i) * 0.05 - 1.5).collect();
                let _ = m.insert_scan(&[1.5; 60], &angles, Pose2::identity());
                let _ = m.run_checks();
            }
        }
        let bytes = seal(FileKind::Grid, &wire::encode(&grid).unwrap());
        if let (Ok(g), true) = (NdtGrid::from_bytes(&bytes), usable) {
            let pts: Vec<[f64; 2]> = (0..30).map(|i| [0.02 * f64::from(i), 0.1]).collect();
            let _ = g.match_scan(&pts, Pose2::identity(), &MatchOptions::default());
        }
    }
}

/// A wire cell: mostly small keys and plausible sums, sometimes anything.
fn cell_strategy() -> impl Strategy<Value = wire::CellV1> {
    (
        prop_oneof![9 => -5i32..5, 1 => any::<i32>()],
        prop_oneof![9 => -5i32..5, 1 => any::<i32>()],
        prop_oneof![9 => 1u64..10, 1 => any::<u64>()],
        proptest::array::uniform2(prop_oneof![9 => -0.1f64..0.1, 1 => any::<f64>()]),
        proptest::array::uniform4(prop_oneof![9 => 0.0f64..0.1, 1 => any::<f64>()]),
    )
        .prop_map(|(ix, iy, count, sum, scatter)| wire::CellV1 {
            ix,
            iy,
            count,
            sum,
            scatter,
        })
}

/// A wire filter record: mostly plausible, sometimes anything.
fn record_strategy() -> impl Strategy<Value = wire::RecordV1> {
    (
        prop_oneof![9 => -5i32..5, 1 => any::<i32>()],
        prop_oneof![9 => -5i32..5, 1 => any::<i32>()],
        prop_oneof![9 => 1u64..20, 1 => any::<u64>()],
        prop_oneof![9 => 0u64..20, 1 => any::<u64>()],
        prop_oneof![9 => 1u32..5, 1 => any::<u32>()],
        prop_oneof![9 => 0u32..2, 1 => any::<u32>()],
        any::<bool>(),
    )
        .prop_map(
            |(ix, iy, first_seen, later, observations, small_observations, seen_in_area1)| {
                wire::RecordV1 {
                    ix,
                    iy,
                    first_seen,
                    last_seen: first_seen.saturating_add(later),
                    observations,
                    small_observations,
                    seen_in_area1,
                }
            },
        )
}
