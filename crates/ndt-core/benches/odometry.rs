//! `cargo bench --bench odometry`: one step of the scan-to-map odometry loop
//! (prediction, rotation search, match, insertion, map window) on a 181-beam
//! SICK-like scan of the synthetic room, with the default settings (2 cm).
//!
//! The loop first runs along a 60-scan path; each measured step then processes
//! a later scan of the path (the first whose step inserts it) from a clone of
//! that loop. `181_beams_2cm` updates the mapper in line (the whole step on
//! one thread, `background_mapper: false`); `181_beams_2cm_mapper_behind` has
//! the default helper thread and also reads the mapper, which waits for the
//! helper to take the scan in: one isolated step cannot overlap the two, so
//! this is the step's latency with the hand-over, not the loop's throughput
//! (for that, the whole Intel log: `examples/replay.rs`, `benches/speed.py`).
//! `181_beams_2cm_poses_only` builds no map (`build_map: false`): the step
//! matches and feeds the matching grid only.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use ndt_core::{Odometry, OdometryConfig, Pose2};

fn polar(pose: Pose2, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let pts = common::scan(&common::room(), pose, 181, std::f64::consts::PI, 0.01, seed);
    pts.iter()
        .map(|p| (p[0].hypot(p[1]), p[1].atan2(p[0])))
        .unzip()
}

fn path(k: u32) -> Pose2 {
    let t = f64::from(k);
    Pose2::new(
        -1.5 + 0.04 * t,
        -0.8 + 0.3 * (t / 12.0).sin(),
        0.4 * (t / 15.0).sin(),
    )
}

fn bench_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("odometry_step");
    for (name, background_mapper, build_map) in [
        ("181_beams_2cm", false, true),
        ("181_beams_2cm_mapper_behind", true, true),
        ("181_beams_2cm_poses_only", false, false),
    ] {
        let config = OdometryConfig {
            background_mapper,
            build_map,
            ..OdometryConfig::default()
        };
        bench_step_with(&mut group, name, config);
    }
    group.finish();
}

fn bench_step_with(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    config: OdometryConfig,
) {
    let mut odo = Odometry::new(config).unwrap_or_else(|e| panic!("{e}"));
    for k in 0..60 {
        let (r, a) = polar(path(k), u64::from(k));
        let odom = path(k).compose(Pose2::new(0.0, 0.0, 0.002 * f64::from(k)));
        odo.step(&r, &a, Some(odom))
            .unwrap_or_else(|e| panic!("{e}"));
    }
    // The measured step: the next scan from the 61st on whose step adds it
    // to the map (if it builds one) and to the matching grid (a step that only matches would
    // measure less than the loop does on average); the scans before it are
    // processed first.
    let scan = |k: u32| {
        let (r, a) = polar(path(k), u64::from(k));
        let odom = path(k).compose(Pose2::new(0.0, 0.0, 0.002 * f64::from(k)));
        (r, a, odom)
    };
    let mut k = 60;
    loop {
        let (r, a, odom) = scan(k);
        let mut probe = odo.clone();
        let inserted = probe
            .step(&r, &a, Some(odom))
            .unwrap_or_else(|e| panic!("{e}"))
            .inserted;
        if (inserted || !config.build_map) && probe.grid_insertions() > odo.grid_insertions() {
            break;
        }
        assert!(k < 70, "no step of scans 60-69 inserts into both maps");
        odo = probe;
        k += 1;
    }
    let (r, a, odom) = scan(k);
    group.throughput(Throughput::Elements(r.len() as u64));
    group.bench_function(name, |b| {
        b.iter_batched_ref(
            || odo.clone(),
            |o| {
                let out = o.step(black_box(&r), black_box(&a), Some(odom));
                // Waits for a mapper behind the loop (at once in line).
                black_box(o.mapper().map(|m| m.grid().len()).ok());
                out
            },
            BatchSize::LargeInput,
        )
    });
}

criterion_group!(benches, bench_step);
criterion_main!(benches);
