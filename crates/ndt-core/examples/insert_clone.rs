//! Profiling harness: criterion's `insert` group (`benches/core.rs`), each
//! insert into a fresh copy of the map, as a plain program.
//!
//! `insert_clone [beams] [n]` (default 683 beams, 2000 inserts): a 2 cm grid
//! takes 8 simulated scans of the tests' room, its default match's
//! distributions are built and one more scan is inserted, as in the group;
//! then `n` times a copy of that grid takes the group's scan, only the
//! insert timed; prints the median insert. Under callgrind,
//! `--toggle-collect='ndt_core::grid::NdtGrid::insert'` counts the timed
//! inserts' instructions (and the 9 of the map's making).

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
use ndt_core::MatchOptions;

fn main() -> Result<(), Box<dyn Error>> {
    let beams = arg(1, 683)?;
    let rounds = arg(2, 2000)?;
    let mut grid = common::room_map(beams, 0.02)?;
    let (pose, points) = common::timed_scan(beams);
    grid.match_scan(&points, pose, &MatchOptions::default())?;
    let (before, first) = common::before_scan(beams);
    grid.insert(&first, before)?;
    let mut times = Vec::with_capacity(rounds);
    for _ in 0..rounds {
        let mut copy = grid.clone();
        let t = Instant::now();
        black_box(copy.insert(black_box(&points), pose))?;
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    println!(
        "{} inserts of {} points into a fresh copy: median {:.1} us",
        times.len(),
        points.len(),
        median(&mut times)
    );
    Ok(())
}
