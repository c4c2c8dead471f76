//! `cargo bench`: insert and match of 180-, 361-, 683- and 2000-point scans
//! on 2 cm and 20 cm grids, and the pyramid update alone (one thread unless
//! a group's name says otherwise; throughput in scan points, in scans for
//! `match_many`).
//!
//! The map is the synthetic room of the tests, built from eight scans; the
//! matched scan is taken 3 cm / 1° away from its guess. `match` uses the
//! default options (pyramid), `match_paper` the paper's method alone,
//! `match_large` matches 2048- to 32000-point scans (2 cm) with and without
//! `MatchOptions::parallel`; `match_many` matches 64 different 683-point
//! scans in one call on one thread and on every core (throughput in scans).
//! `insert` keeps the prepared distributions of a default match up to date
//! (as in a SLAM loop), `insert_sums_only` has none prepared (eq. 6 and the
//! pyramid's sums only), `pyramid_update` is the pyramid's part of that; both
//! insert into a map that has taken one insert since it was built, and each
//! timed insert goes to a fresh clone of it; `insert_loop` inserts into one
//! grid scan after scan, each scan matched first (untimed), as a loop does;
//! `insert_many` inserts batches of that loop's scans in one call each.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use ndt_core::grid::DEFAULT_LEVELS;
use ndt_core::nalgebra::Vector2;
use ndt_core::pyramid::Pyramid;
use ndt_core::{CellKey, MatchOptions, NdtGrid, Pose2};

const BEAMS: [usize; 4] = [180, 361, 683, 2000];
const CELLS: [f64; 2] = [0.02, 0.2];

fn scan(beams: usize, pose: Pose2, seed: u64) -> Vec<[f64; 2]> {
    common::room_scan(beams, pose, seed)
}

fn map(beams: usize, cell: f64) -> NdtGrid {
    common::room_map(beams, cell).unwrap_or_else(|e| panic!("{e}"))
}

fn bench_insert(c: &mut Criterion) {
    for (name, prepared) in [("insert", true), ("insert_sums_only", false)] {
        bench_insert_with(c, name, prepared);
    }
}

fn bench_insert_with(c: &mut Criterion, name: &str, prepared: bool) {
    let mut group = c.benchmark_group(name);
    for cell in CELLS {
        for beams in BEAMS {
            let grid = map(beams, cell);
            let (pose, pts) = common::timed_scan(beams);
            // A SLAM loop's map has its distributions built: insert keeps them
            // up to date, and that is part of what is timed. One more scan is
            // inserted first, as a loop inserts after every build. Until
            // session 52 a freshly built table was exactly full, and its
            // first insert copied it whole (once per build in a loop, but on
            // every timed clone here: at 2 cm and 683 points one level's 426
            // entries); now a built table has the room of its level's sums
            // (benches/SPEED_LOG.md, sessions 51 and 52).
            let mut grid = grid;
            if prepared {
                let _ = grid.match_scan(&pts, pose, &MatchOptions::default());
            }
            let (before, first) = common::before_scan(beams);
            grid.insert(&first, before)
                .unwrap_or_else(|e| panic!("{e}"));
            group.throughput(Throughput::Elements(pts.len() as u64));
            group.bench_with_input(
                BenchmarkId::new(format!("cell_{}cm", cell * 100.0), beams),
                &pts,
                |b, pts| {
                    b.iter_batched_ref(
                        || grid.clone(),
                        |g| g.insert(black_box(pts), pose),
                        criterion::BatchSize::LargeInput,
                    )
                },
            );
        }
    }
    group.finish();
}

/// Inserts as a SLAM loop makes them, with no clone: one grid takes scans
/// from a ring of 64 poses through the room, each matched first (untimed,
/// so the distributions are built and warm, as after the loop's match);
/// only the insert is timed. The room is bounded, so after the first round
/// the map keeps its cells and their counts grow.
fn bench_insert_loop(c: &mut Criterion) {
    let mut group = c.benchmark_group("insert_loop");
    for beams in BEAMS {
        let mut grid = map(beams, 0.02);
        let ring = ring(beams);
        let options = MatchOptions::default();
        let mean = ring.iter().map(|(_, p)| p.len()).sum::<usize>() / ring.len();
        group.throughput(Throughput::Elements(mean as u64));
        let mut next = 0usize;
        group.bench_function(BenchmarkId::new("cell_2cm", beams), |b| {
            b.iter_custom(|iters| {
                let mut timed = std::time::Duration::ZERO;
                for _ in 0..iters {
                    let (pose, pts) = &ring[next % ring.len()];
                    next += 1;
                    let _ = grid.match_scan(pts, *pose, &options);
                    let t = std::time::Instant::now();
                    let changed = grid.insert(black_box(pts), *pose);
                    timed += t.elapsed();
                    black_box(changed).unwrap_or_else(|e| panic!("{e}"));
                }
                timed
            })
        });
    }
    group.finish();
}

/// 64 scans from a ring of poses through the room, 0.1 rad and about 0.1 m
/// apart, each with its pose.
fn ring(beams: usize) -> Vec<(Pose2, Vec<[f64; 2]>)> {
    (0..64u32)
        .map(|i| {
            let a = f64::from(i) * std::f64::consts::TAU / 64.0;
            let pose = Pose2::new(1.2 * a.cos(), 0.8 * a.sin(), a + 1.57);
            (pose, scan(beams, pose, 100 + u64::from(i)))
        })
        .collect()
}

/// `NdtGrid::insert_many`: batches of 1, 4, 16 and 64 consecutive 683-point
/// scans of `insert_loop`'s ring in one call each, into one grid, matched
/// first (untimed) so its distributions are built; throughput in scan
/// points, so that a batch's rate compares with `insert_loop`'s.
fn bench_insert_many(c: &mut Criterion) {
    let mut group = c.benchmark_group("insert_many");
    let mut grid = map(683, 0.02);
    let ring = ring(683);
    let options = MatchOptions::default();
    for size in [1usize, 4, 16, 64] {
        let points: usize = ring.iter().take(size).map(|(_, p)| p.len()).sum();
        group.throughput(Throughput::Elements(points as u64));
        let mut next = 0usize;
        group.bench_function(BenchmarkId::new("cell_2cm_683", size), |b| {
            b.iter_custom(|iters| {
                let mut timed = std::time::Duration::ZERO;
                for _ in 0..iters {
                    let batch: Vec<_> = (0..size).map(|k| &ring[(next + k) % ring.len()]).collect();
                    next += size;
                    let (scans, poses): (Vec<&[[f64; 2]]>, Vec<Pose2>) =
                        batch.iter().map(|(pose, p)| (p.as_slice(), *pose)).unzip();
                    let _ = grid.match_scan(scans[0], poses[0], &options);
                    let t = std::time::Instant::now();
                    let done = grid.insert_many(black_box(&scans), &poses);
                    timed += t.elapsed();
                    done.unwrap_or_else(|e| panic!("{e}"));
                }
                timed
            })
        });
    }
    group.finish();
}

/// `Pyramid::add` alone: eq. (6) on the fine level and the coarser levels
/// re-summed above the changed cells (6 levels).
fn bench_pyramid(c: &mut Criterion) {
    let mut group = c.benchmark_group("pyramid_update");
    for cell in CELLS {
        for beams in BEAMS {
            let mut pyramid = Pyramid::new(cell, DEFAULT_LEVELS);
            for (pose, seed) in common::room_poses() {
                pyramid.add(&staged(&scan(beams, pose, seed), pose, cell));
            }
            let (pose, pts) = common::timed_scan(beams);
            let batch = staged(&pts, pose, cell);
            group.throughput(Throughput::Elements(batch.len() as u64));
            group.bench_with_input(
                BenchmarkId::new(format!("cell_{}cm", cell * 100.0), beams),
                &batch,
                |b, batch| {
                    b.iter_batched_ref(
                        || pyramid.clone(),
                        |p| p.add(black_box(batch)),
                        criterion::BatchSize::LargeInput,
                    )
                },
            );
        }
    }
    group.finish();
}

/// Map-frame points with their fine keys, as `NdtGrid::insert` stages them.
fn staged(points: &[[f64; 2]], pose: Pose2, cell: f64) -> Vec<(CellKey, Vector2<f64>)> {
    points
        .iter()
        .filter_map(|p| {
            let w = pose.transform(Vector2::new(p[0], p[1]));
            CellKey::of(w, 1.0 / cell).map(|k| (k, w))
        })
        .collect()
}

/// The paper's method alone (§IV-A on the fine grid only).
fn paper() -> MatchOptions {
    MatchOptions::paper()
}

fn bench_match(c: &mut Criterion) {
    for (name, options) in [("match", MatchOptions::default()), ("match_paper", paper())] {
        bench_match_with(c, name, &options);
    }
}

fn bench_match_with(c: &mut Criterion, name: &str, options: &MatchOptions) {
    let mut group = c.benchmark_group(name);
    for cell in CELLS {
        for beams in BEAMS {
            let grid = map(beams, cell);
            let (truth, pts) = common::timed_scan(beams);
            let guess = Pose2::new(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.017);
            // Build the distributions once, as a SLAM loop's map already has them.
            let _ = grid.match_scan(&pts, guess, options);
            group.throughput(Throughput::Elements(pts.len() as u64));
            group.bench_with_input(
                BenchmarkId::new(format!("cell_{}cm", cell * 100.0), beams),
                &pts,
                |b, pts| b.iter(|| grid.match_scan(black_box(pts), guess, options)),
            );
        }
    }
    group.finish();
}

/// Large scans, one thread against `parallel` (rayon, all cores).
fn bench_large(c: &mut Criterion) {
    let mut group = c.benchmark_group("match_large");
    group.sample_size(20);
    let grid = map(2000, 0.02);
    let truth = Pose2::new(0.1, -0.05, 0.3);
    let guess = Pose2::new(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.017);
    for beams in [2048usize, 4096, 8192, 16384, 32000] {
        let pts = scan(beams, truth, 42);
        group.throughput(Throughput::Elements(pts.len() as u64));
        for parallel in [false, true] {
            let options = MatchOptions {
                parallel,
                ..MatchOptions::default()
            };
            let _ = grid.match_scan(&pts, guess, &options);
            let name = if parallel { "parallel" } else { "one_thread" };
            group.bench_with_input(BenchmarkId::new(name, beams), &pts, |b, pts| {
                b.iter(|| grid.match_scan(black_box(pts), guess, &options))
            });
        }
    }
    group.finish();
}

/// 64 different 683-point scans, each 3 cm / 1° off, in one `match_many`
/// call: on the calling thread alone and with helper threads on every core.
fn bench_many(c: &mut Criterion) {
    let mut group = c.benchmark_group("match_many");
    group.sample_size(20);
    let grid = map(683, 0.02);
    let (scans, guesses): (Vec<_>, Vec<_>) = (0..64u32)
        .map(|i| {
            let a = f64::from(i) * 0.1;
            let truth = Pose2::new(0.2 * a.cos(), 0.15 * a.sin(), a);
            let guess = Pose2::new(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.017);
            (scan(683, truth, 100 + u64::from(i)), guess)
        })
        .unzip();
    let views: Vec<&[[f64; 2]]> = scans.iter().map(Vec::as_slice).collect();
    let options = MatchOptions::default();
    group.throughput(Throughput::Elements(views.len() as u64));
    for (name, threads) in [("one_thread", Some(1)), ("every_core", None)] {
        let _ = grid.match_many(&views, &guesses, &options, None, threads);
        group.bench_function(name, |b| {
            b.iter(|| grid.match_many(black_box(&views), &guesses, &options, None, threads))
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    bench_insert,
    bench_insert_loop,
    bench_insert_many,
    bench_pyramid,
    bench_match,
    bench_large,
    bench_many
);
criterion_main!(benches);
