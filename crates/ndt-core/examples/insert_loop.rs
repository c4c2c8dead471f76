//! Profiling harness: criterion's `insert_loop` group (`benches/core.rs`)
//! as a plain program, for instruction counts under valgrind.
//!
//! `insert_loop [beams] [n]` (default 683 beams, 300 rounds): a 2 cm grid
//! takes 8 simulated scans of the tests' room, then `n` times one of 64
//! scans from a ring of poses is matched with the default options (so the
//! distributions are built, as in a SLAM loop) and inserted; prints the
//! mean time of an insert and of a match. `insert_loop [beams] [n] [batch]`
//! with `batch > 1`: `n` rounds of `batch` consecutive ring scans, the
//! first matched, all inserted by one `insert_many` call (time per scan).

#[path = "../tests/common/mod.rs"]
mod common;

#[path = "common/args.rs"]
mod args;
use args::arg;

use std::error::Error;
use std::time::Instant;

use ndt_core::{MatchOptions, Pose2};

fn main() -> Result<(), Box<dyn Error>> {
    let beams = arg(1, 683)?;
    let rounds = arg(2, 300)?;
    let batch = arg(3, 1)?;
    let mut grid = common::room_map(beams, 0.02)?;
    let ring: Vec<(Pose2, Vec<[f64; 2]>)> = (0..64u32)
        .map(|i| {
            let a = f64::from(i) * std::f64::consts::TAU / 64.0;
            let pose = Pose2::new(1.2 * a.cos(), 0.8 * a.sin(), a + 1.57);
            (pose, common::room_scan(beams, pose, 100 + u64::from(i)))
        })
        .collect();
    let options = MatchOptions::default();
    let (mut t_insert, mut t_match) = (0.0, 0.0);
    if batch > 1 {
        // Rounds of `batch` consecutive ring scans: the first matched, all
        // inserted by one insert_many call.
        for k in 0..rounds {
            let (scans, poses): (Vec<&[[f64; 2]]>, Vec<Pose2>) = (0..batch)
                .map(|j| {
                    let (pose, points) = &ring[(k * batch + j) % ring.len()];
                    (points.as_slice(), *pose)
                })
                .unzip();
            let t = Instant::now();
            grid.match_scan(scans[0], poses[0], &options)?;
            t_match += t.elapsed().as_secs_f64();
            let t = Instant::now();
            grid.insert_many(&scans, &poses)?;
            t_insert += t.elapsed().as_secs_f64();
        }
        let per = 1e6 / rounds.max(1) as f64;
        println!(
            "{rounds} rounds of {batch} scans of {beams} beams: insert_many {:.1} us a scan, match {:.1} us",
            t_insert * per / batch as f64,
            t_match * per
        );
        return Ok(());
    }
    for k in 0..rounds {
        let (pose, points) = &ring[k % ring.len()];
        let t = Instant::now();
        grid.match_scan(points, *pose, &options)?;
        t_match += t.elapsed().as_secs_f64();
        let t = Instant::now();
        grid.insert(points, *pose)?;
        t_insert += t.elapsed().as_secs_f64();
    }
    let per = 1e6 / rounds.max(1) as f64;
    println!(
        "{rounds} rounds of {beams} beams: insert {:.1} us, match {:.1} us",
        t_insert * per,
        t_match * per
    );
    Ok(())
}
