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

use ndt_core::{MatchOptions, NdtGrid, Pose2};

/// Scans in the map before the timed inserts (as `speed.py`).
const PREFILL: usize = 100;

/// One scan: scan-frame points and the pose they were seen from.
type Scan = (Vec<[f64; 2]>, Pose2);

/// The scans of `bytes` (see `benches/dump_insert_case.py`).
fn scans(bytes: &[u8]) -> Result<Vec<Scan>, Box<dyn Error>> {
    let mut words = bytes
        .chunks_exact(8)
        .map(|w| <[u8; 8]>::try_from(w).unwrap_or([0; 8]));
    let mut out = Vec::new();
    while let Some(count) = words.next() {
        let n = usize::try_from(i64::from_le_bytes(count))?;
        let mut values = words.by_ref().take(2 * n + 3).map(f64::from_le_bytes);
        let points: Vec<[f64; 2]> = (0..n)
            .map_while(|_| Some([values.next()?, values.next()?]))
            .collect();
        match (values.next(), values.next(), values.next()) {
            (Some(x), Some(y), Some(theta)) if points.len() == n => {
                out.push((points, Pose2::new(x, y, theta)));
            }
            _ => return Err("the file ends inside a scan".into()),
        }
    }
    Ok(out)
}

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
    times.sort_by(f64::total_cmp);
    println!(
        "{} inserts: median {:.1} us; the map holds {} cells",
        times.len(),
        times.get(times.len() / 2).copied().unwrap_or(f64::NAN),
        grid.len()
    );
    Ok(())
}
