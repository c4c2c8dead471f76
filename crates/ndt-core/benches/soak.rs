//! `cargo bench --bench soak`: the long-run memory test of issue 6.
//!
//! A robot drives an ellipse (4.4 m × 0.6 m, 400 scans a lap) round and round
//! the synthetic 6 m × 4 m room of the tests with a 181-beam scanner (σ = 1 cm
//! range noise, fresh noise every scan, and a few invalid readings per scan:
//! NaN, ±inf, 0, negative), and
//!
//! 1. feeds `SOAK_SCANS` scans (default 1 000 000) with their true poses
//!    through a [`Mapper`] (grid + §V filter, default options);
//! 2. then runs `SOAK_ODOMETRY_SCANS` scans (default 1 000 000) through the
//!    [`Odometry`] loop (default settings; odometry = true pose with a slow
//!    drift), whose pose history grows by design (24 bytes a scan).
//!
//! Every `SOAK_EVERY` scans (default 10 000) it samples the resident memory
//! (`VmRSS`, and its peak `VmHWM`, from `/proc/self/status`) and the cell
//! counts, printing them and writing `SOAK_OUT` (default `target/soak.csv` of
//! the workspace; a relative `SOAK_OUT` is relative to `crates/ndt-core`);
//! `python benches/soak_plot.py target/soak.csv` draws it. A short run:
//! `SOAK_SCANS=20000 SOAK_ODOMETRY_SCANS=2000 cargo bench --bench soak`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::fmt::Write as _;
use std::time::Instant;

use ndt_core::{Mapper, MapperOptions, Odometry, OdometryConfig, Pose2};

/// Scans per lap of the ellipse.
const LAP: u64 = 400;
/// Beams per scan.
const BEAMS: usize = 181;

fn env(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.replace('_', "").parse().ok())
        .unwrap_or(default)
}

/// The true pose of scan `k`: on the ellipse, facing along it.
fn pose(k: u64) -> Pose2 {
    let s = std::f64::consts::TAU * (k % LAP) as f64 / LAP as f64;
    let (x, y) = (2.2 * s.cos(), 0.3 * s.sin());
    let (dx, dy) = (-2.2 * s.sin(), 0.3 * s.cos());
    Pose2::new(x, y, dy.atan2(dx))
}

/// Ranges and angles of scan `k`, with a few invalid readings.
fn scan(walls: &[common::Segment], k: u64) -> (Vec<f64>, Vec<f64>) {
    let pts = common::scan(walls, pose(k), BEAMS, std::f64::consts::PI, 0.01, k);
    let (mut r, a): (Vec<f64>, Vec<f64>) = pts
        .iter()
        .map(|p| (p[0].hypot(p[1]), p[1].atan2(p[0])))
        .unzip();
    let bad = [f64::NAN, f64::INFINITY, 0.0, -1.0, f64::NEG_INFINITY];
    for (j, v) in bad.iter().enumerate() {
        let i = ((k as usize) * 37 + j * 53) % r.len();
        r[i] = *v;
    }
    (r, a)
}

/// `(VmRSS, VmHWM)` of this process \[KiB\].
fn memory_kib() -> (u64, u64) {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| {
        status
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|v| v.parse().ok())
            .unwrap_or(0)
    };
    (field("VmRSS:"), field("VmHWM:"))
}

struct Log {
    csv: String,
    start: Instant,
}

impl Log {
    fn sample(&mut self, phase: &str, scans: u64, cells: usize, tracked: usize, poses: usize) {
        let (rss, hwm) = memory_kib();
        let t = self.start.elapsed().as_secs_f64();
        println!(
            "{phase:9} scans {scans:>8}  rss {rss:>7} KiB  peak {hwm:>7} KiB  cells {cells:>6}  \
             filter records {tracked:>6}  poses {poses:>7}  {t:8.1} s"
        );
        let _ = writeln!(
            self.csv,
            "{phase},{scans},{rss},{hwm},{cells},{tracked},{poses},{t:.3}"
        );
    }
}

fn main() {
    let scans = env("SOAK_SCANS", 1_000_000);
    let odo_scans = env("SOAK_ODOMETRY_SCANS", 1_000_000);
    let every = env("SOAK_EVERY", 10_000).max(1);
    // `cargo bench` runs in the crate's directory: default to the workspace's target/.
    let out = std::env::var("SOAK_OUT")
        .unwrap_or_else(|_| concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/soak.csv").into());
    let walls = common::room();
    let mut log = Log {
        csv: "phase,scans,rss_kib,peak_kib,cells,filter_records,poses,elapsed_s\n".into(),
        start: Instant::now(),
    };
    log.sample("start", 0, 0, 0, 0);

    let mut mapper =
        Mapper::new(0.02, MapperOptions::default()).unwrap_or_else(|e| panic!("mapper: {e}"));
    for k in 1..=scans {
        let (r, a) = scan(&walls, k);
        mapper
            .insert_scan(&r, &a, pose(k))
            .unwrap_or_else(|e| panic!("scan {k}: {e}"));
        if k % every == 0 || k == scans {
            let tracked = mapper.filter().tracked_cells();
            log.sample("mapper", k, mapper.grid().len(), tracked, 0);
        }
    }
    let mapper_time = log.start.elapsed().as_secs_f64();
    drop(mapper);

    let mut odo =
        Odometry::new(OdometryConfig::default()).unwrap_or_else(|e| panic!("odometry: {e}"));
    for k in 1..=odo_scans {
        let (r, a) = scan(&walls, k);
        // Wheel odometry: the true pose with a slow heading drift.
        let drift = Pose2::new(0.0, 0.0, 1e-5 * k as f64);
        odo.step(&r, &a, Some(pose(k).compose(drift)))
            .unwrap_or_else(|e| panic!("odometry scan {k}: {e}"));
        if k % every == 0 || k == odo_scans {
            let m = odo
                .mapper()
                .unwrap_or_else(|e| panic!("odometry scan {k}: {e}"));
            log.sample(
                "odometry",
                k,
                odo.grid().len(),
                m.filter().tracked_cells(),
                odo.poses().len(),
            );
        }
    }
    let total = log.start.elapsed().as_secs_f64();
    println!(
        "mapper: {scans} scans in {mapper_time:.1} s; odometry: {odo_scans} scans in {:.1} s",
        total - mapper_time
    );
    if let Some(dir) = std::path::Path::new(&out).parent() {
        let _ = std::fs::create_dir_all(dir);
    }
    match std::fs::write(&out, &log.csv) {
        Ok(()) => println!("wrote {out}"),
        Err(e) => eprintln!("cannot write {out}: {e}"),
    }
}
