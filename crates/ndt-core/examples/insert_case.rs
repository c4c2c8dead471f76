//! Profiling harness: `benches/speed.py`'s insert target without Python.
//!
//! `insert_case FILE [n]` reads the scans `benches/dump_insert_case.py`
//! wrote (the simulated URG-04LX scans the 50 µs insert is judged
//! on), puts the first 100 into a 2 cm grid, then `n` times (default 300,
//! at most the scans left) matches the next scan with the default options
//! (untimed: the distributions are built, as in a SLAM loop) and inserts
//! it, timed; prints the median insert. Under callgrind,
//! `--toggle-collect='ndt_core::grid::NdtGrid::insert'` counts every
//! insert's instructions, the first 100 included.

use std::error::Error;
use std::time::Instant;

use ndt_core::{MatchOptions, NdtGrid};

#[path = "common/insert_scans.rs"]
mod insert_scans;
use insert_scans::{median, scans, PREFILL};

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: insert_case FILE [n]")?;
    let rounds: usize = args.next().map_or(Ok(300), |s| s.parse())?;
    let scans = scans(&std::fs::read(path)?)?;
    if scans.len() <= PREFILL {
        return Err(format!("{} scans: need more than {PREFILL}", scans.len()).into());
    }
    let mut grid = NdtGrid::new(0.02)?;
    for (points, pose) in &scans[..PREFILL] {
        grid.insert(points, *pose)?;
    }
    let options = MatchOptions::default();
    let mut times = Vec::with_capacity(rounds);
    for (points, pose) in scans[PREFILL..].iter().take(rounds) {
        grid.match_scan(points, *pose, &options)?;
        let t = Instant::now();
        grid.insert(points, *pose)?;
        times.push(t.elapsed().as_secs_f64() * 1e6);
    }
    println!(
        "{} inserts: median {:.1} us; the map holds {} cells",
        times.len(),
        median(&mut times),
        grid.len()
    );
    Ok(())
}
