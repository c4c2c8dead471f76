//! Profiling harness: criterion's `match_large` group (`benches/core.rs`) as
//! a plain program, one scan size and one mode a run.
//!
//! `large_probe [points] [n] [parallel]` (default 32000 points, 30 matches,
//! 0): a 2 cm grid takes 8 simulated 2000-beam scans of the tests' room;
//! then a scan of `points` points taken at (0.1 m, −0.05 m, 0.3 rad) is
//! matched `n` times from 3 cm / 2 cm / 1° off, with
//! `MatchOptions::parallel` when the third argument is 1; prints the median
//! match, its iterations and time a point and iteration, and the pose (its
//! bits: `{:?}`), which the thread count must not change.
//! `RAYON_NUM_THREADS=1` gives the parallel layout on one thread.

#[path = "../tests/common/mod.rs"]
mod common;

#[path = "common/args.rs"]
mod args;
use args::arg;

#[path = "common/insert_scans.rs"]
#[allow(dead_code)]
mod insert_scans;

use std::error::Error;
use std::hint::black_box;
use std::time::Instant;

use insert_scans::median;
use ndt_core::{MatchOptions, Pose2};

fn main() -> Result<(), Box<dyn Error>> {
    let points = arg(1, 32000)?;
    let rounds = arg(2, 30)?.max(1);
    let parallel = arg(3, 0)? == 1;
    let grid = common::room_map(2000, 0.02)?;
    let truth = Pose2::new(0.1, -0.05, 0.3);
    let guess = Pose2::new(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.017);
    let scan = common::room_scan(points, truth, 42);
    let options = MatchOptions {
        parallel,
        ..MatchOptions::default()
    };
    // Builds the distributions, as a SLAM loop's map already has them.
    let result = grid.match_scan(&scan, guess, &options)?;
    let mut times = Vec::with_capacity(rounds);
    for _ in 0..rounds {
        let t0 = Instant::now();
        black_box(grid.match_scan(black_box(&scan), guess, &options)?);
        times.push(t0.elapsed().as_secs_f64());
    }
    let time = median(&mut times);
    // Scans of other sizes may take another number of Newton steps: the
    // time a point and step compares them.
    let per_step = time / (scan.len() as f64 * f64::from(result.iterations.max(1)));
    println!(
        "{} points, parallel {parallel}: median {:.3} ms over {rounds} matches, {} iterations ({:.1} ns a point an iteration); pose {:?}",
        scan.len(),
        time * 1e3,
        result.iterations,
        per_step * 1e9,
        result.pose
    );
    Ok(())
}
