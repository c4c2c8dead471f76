//! Profiling harness: a log's scans from a dump of `benches/dump_scans.py`.
//!
//! `replay <dump> odometry [reps] [inline|loop-only|poses-only|no-filter]`: `Odometry`
//! (default configuration; `inline`: `background_mapper: false`;
//! `loop-only`: the mapper takes the first scan only, so the loop runs
//! without a mapper's work beside it, with the same poses; `poses-only`:
//! `build_map: false`, no mapper at all, hash 0; `no-filter`: the mapper
//! without the §V elimination, so its thread only inserts) over every scan, `reps` times;
//! prints the time per scan, the last pose and a hash of the mapper (every
//! pyramid level's sums and the §V filter's records), so two builds can be
//! compared for bit-identical maps.
//! `replay <dump> matchhash`: the first 3000 scans matched with the default
//! options against a map that takes every third scan and loses every 17th
//! cell (in key order) every 50 scans; prints a hash of every pose's and
//! score's bits, so two builds can be compared for bit-identical results.
//! `replay <dump> mapwork [reps]`: the work of the loop's matching grid
//! alone. `Odometry` runs over the log once to find the scans it inserts
//! and their poses; then, `reps` times, a new grid takes them in order
//! (its distributions prepared by a match before the second insertion, as
//! in the loop) and loses the cells of the loop's map window, as
//! `Odometry` does; prints the time of the inserts and of the removals.
//! `replay <dump> threads [reps]`: `speed.py`'s thread section without
//! Python. `Odometry` (loop only) over the first 3000 scans gives poses; a
//! 2 cm grid takes every third scan; then, `reps` times, the 3000 scans are
//! matched from their poses moved by a fixed offset on one thread, then
//! split alternately between two threads on that one grid, then likewise on
//! two clones of it, then by `NdtGrid::match_many` on one thread and on
//! every core; prints each run's matches per second, the ratios, and
//! whether the poses were the same.

use std::collections::VecDeque;
use std::error::Error;
use std::time::Instant;

use ndt_core::odometry::{Odometry, OdometryConfig};
use ndt_core::{points_from_ranges, CellKey, Mapper, MatchOptions, NdtGrid, Pose2};
use rustc_hash::FxHashMap;

type Scan = (Vec<f64>, Vec<f64>, Option<Pose2>);

fn read_dump(path: &str) -> Result<Vec<Scan>, Box<dyn Error>> {
    let buf = std::fs::read(path)?;
    let mut words = buf
        .chunks_exact(8)
        .map(|c| <[u8; 8]>::try_from(c).map_err(|e| e.to_string()));
    let mut next =
        || -> Result<[u8; 8], Box<dyn Error>> { Ok(words.next().ok_or("truncated dump")??) };
    let mut scans = Vec::new();
    while scans.len() * 8 < buf.len() {
        let Ok(n) = next().map(i64::from_le_bytes) else {
            break;
        };
        let mut floats = |k: usize| -> Result<Vec<f64>, Box<dyn Error>> {
            (0..k).map(|_| next().map(f64::from_le_bytes)).collect()
        };
        let ranges = floats(n as usize)?;
        let angles = floats(n as usize)?;
        let o = floats(3)?;
        let odom = (!o[0].is_nan()).then(|| Pose2::new(o[0], o[1], o[2]));
        scans.push((ranges, angles, odom));
    }
    Ok(scans)
}

/// CPU seconds this thread has used (user + system, from
/// `/proc/thread-self/stat`, 10 ms ticks; 0 where that file is absent).
fn thread_cpu() -> f64 {
    cpu_of("/proc/thread-self/stat")
}

/// CPU seconds the whole process has used (every thread, joined ones too).
fn process_cpu() -> f64 {
    cpu_of("/proc/self/stat")
}

/// User + system CPU seconds of a `stat` file of `/proc`.
fn cpu_of(path: &str) -> f64 {
    let stat = std::fs::read_to_string(path).unwrap_or_default();
    // Fields after the command name (which may hold spaces) end with ')'.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let ticks: f64 = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse::<f64>().ok())
        .sum();
    ticks / 100.0
}

fn odometry(scans: &[Scan], reps: usize, variant: Option<&str>) -> Result<(), Box<dyn Error>> {
    let mut config = OdometryConfig {
        background_mapper: variant != Some("inline"),
        ..OdometryConfig::default()
    };
    if variant == Some("loop-only") {
        config.insert_distance = 1e9;
        config.insert_angle = 1e9;
    }
    config.build_map = variant != Some("poses-only");
    if variant == Some("no-filter") {
        config.mapper.outlier_filter = false;
    }
    for _ in 0..reps {
        let mut odo = Odometry::new(config)?;
        let t = Instant::now();
        let (cpu, all) = (thread_cpu(), process_cpu());
        for (r, a, o) in scans {
            odo.step(r, a, *o)?;
        }
        let cpu = thread_cpu() - cpu;
        // Wait for the mapper (behind the loop by default) to take in the
        // last scans: part of the run.
        let map = odo.mapper().ok();
        let cells = map.as_ref().map_or(0, |m| m.grid().len());
        let s = t.elapsed().as_secs_f64();
        let helper = process_cpu() - all - cpu;
        // Not part of the run.
        let hash = map.as_ref().map_or(0, |m| mapper_hash(m));
        drop(map);
        let last = odo.poses().last().copied().unwrap_or_default();
        println!(
            "{} scans {s:.3} s ({cpu:.2} s CPU on the loop's thread, {helper:.2} s on others) {:.4} ms/scan, {} inserted, {cells} mapper cells (hash {:016x}), last pose {:.12} {:.12} {:.12}",
            scans.len(),
            1e3 * s / scans.len() as f64,
            odo.insertions(),
            hash,
            last.x,
            last.y,
            last.theta
        );
    }
    Ok(())
}

/// A hash of every level's sums (in key order) and the filter's records.
fn mapper_hash(mapper: &Mapper) -> u64 {
    let mut hash: u64 = 0;
    let mut add = |v: u64| hash = hash.rotate_left(5) ^ v;
    let grid = mapper.grid();
    for l in 0..grid.levels() {
        let Some(level) = grid.level(l) else { break };
        let mut cells: Vec<_> = level.cells().iter().collect();
        cells.sort_unstable_by_key(|(k, _)| *k);
        for (k, c) in cells {
            add(u64::from(k.ix as u32) << 32 | u64::from(k.iy as u32));
            add(c.count);
            for v in c.sum.iter().chain(c.scatter.iter()) {
                add(v.to_bits());
            }
        }
    }
    for (k, info) in mapper.filter().cell_records() {
        add(u64::from(k.ix as u32) << 32 | u64::from(k.iy as u32));
        add(info.first_seen ^ info.last_seen.rotate_left(32));
        add(u64::from(info.observations) << 32 | u64::from(info.small_observations));
        add(u64::from(info.seen_in_area1));
    }
    hash
}

fn matchhash(scans: &[Scan]) -> Result<(), Box<dyn Error>> {
    let options = MatchOptions::default();
    let mut grid = NdtGrid::new(0.02)?;
    let mut hash: u64 = 0;
    let mut pose = scans.first().and_then(|s| s.2).unwrap_or_default();
    let t = Instant::now();
    for (i, (r, a, o)) in scans.iter().take(3000).enumerate() {
        let points = points_from_ranges(r, a, 0.0, 30.0)?;
        if !grid.is_empty() {
            let step = match (scans[i - 1].2, *o) {
                (Some(prev), Some(now)) => prev.between(now),
                _ => Pose2::identity(),
            };
            let res = grid.match_scan(&points, pose.compose(step), &options)?;
            for v in res.pose.to_array().into_iter().chain([res.score]) {
                hash = hash.rotate_left(5) ^ v.to_bits();
            }
            pose = res.pose;
        }
        if i % 3 == 0 {
            grid.insert(&points, pose)?;
        }
        if i % 50 == 0 {
            // Sorted: the same cells whatever order the grid lists them in.
            let mut keys: Vec<_> = grid.keys().collect();
            keys.sort_unstable();
            let keys: Vec<_> = keys.into_iter().step_by(17).collect();
            grid.remove_cells(&keys);
        }
    }
    println!("hash {hash:016x} in {:.3} s", t.elapsed().as_secs_f64());
    Ok(())
}

fn mapwork(scans: &[Scan], reps: usize) -> Result<(), Box<dyn Error>> {
    let config = OdometryConfig::default();
    let mut odo = Odometry::new(config)?;
    let mut inserted = Vec::new();
    for (r, a, o) in scans {
        if odo.step(r, a, *o)?.inserted {
            let points = points_from_ranges(r, a, config.min_range, config.max_range)?;
            inserted.push((points, odo.poses().last().copied().unwrap_or_default()));
        }
    }
    for _ in 0..reps {
        let mut grid = NdtGrid::new(config.cell_size)?;
        // The map window as `Odometry` keeps it: the insertion that last hit
        // each cell, and the cells of each of the last `map_window` ones.
        let mut stamps: FxHashMap<CellKey, usize> = FxHashMap::default();
        let mut window: VecDeque<(usize, Vec<CellKey>)> = VecDeque::new();
        let (mut insert, mut remove) = (0.0, 0.0);
        for (n, (points, pose)) in inserted.iter().enumerate() {
            if n == 1 {
                // A loop has matched before its second insertion.
                grid.match_scan(points, *pose, &config.matcher)?;
            }
            let t = Instant::now();
            let touched = grid.insert(points, *pose)?;
            insert += t.elapsed().as_secs_f64();
            for &key in &touched {
                stamps.insert(key, n);
            }
            window.push_back((n, touched));
            let mut stale = Vec::new();
            while window.len() > config.map_window {
                let Some((m, keys)) = window.pop_front() else {
                    break;
                };
                stale.extend(keys.into_iter().filter(|k| stamps.get(k) == Some(&m)));
            }
            for key in &stale {
                stamps.remove(key);
            }
            let t = Instant::now();
            grid.remove_cells(&stale);
            remove += t.elapsed().as_secs_f64();
        }
        let n = inserted.len().max(1) as f64;
        println!(
            "{} insertions: insert {insert:.3} s ({:.1} us each), window removals {remove:.3} s ({:.1} us each); {} cells",
            inserted.len(),
            1e6 * insert / n,
            1e6 * remove / n,
            grid.len()
        );
    }
    Ok(())
}

fn threads(scans: &[Scan], reps: usize) -> Result<(), Box<dyn Error>> {
    let scans = &scans[..scans.len().min(3000)];
    let mut odo = Odometry::new(OdometryConfig {
        build_map: false,
        ..OdometryConfig::default()
    })?;
    let mut jobs = Vec::with_capacity(scans.len());
    for (r, a, o) in scans {
        odo.step(r, a, *o)?;
        let pose = odo.poses().last().copied().unwrap_or_default();
        jobs.push((points_from_ranges(r, a, 0.0, 30.0)?, pose));
    }
    let mut grid = NdtGrid::new(0.02)?;
    for (points, pose) in jobs.iter().step_by(3) {
        grid.insert(points, *pose)?;
    }
    let options = MatchOptions::default();
    let offset = Pose2::new(0.03, -0.02, 0.01);
    let run = |grids: [&NdtGrid; 2], split: bool| -> Result<(f64, Vec<Pose2>), String> {
        let work = |grid: &NdtGrid, part: usize| -> Result<Vec<Pose2>, String> {
            let stride = if split { 2 } else { 1 };
            (jobs.iter().skip(part).step_by(stride))
                .map(|(p, g)| grid.match_scan(p, g.compose(offset), &options))
                .map(|r| r.map(|m| m.pose).map_err(|e| e.to_string()))
                .collect()
        };
        let t = Instant::now();
        let parts = if split {
            std::thread::scope(|s| {
                let h = [0, 1].map(|k| s.spawn(move || work(grids[k], k)));
                h.map(|h| h.join().unwrap_or_else(|_| Err("a thread panicked".into())))
            })
        } else {
            [work(grids[0], 0), Ok(Vec::new())]
        };
        let rate = jobs.len() as f64 / t.elapsed().as_secs_f64();
        let [a, b] = parts;
        let (a, b) = (a?, b?);
        let mut poses = Vec::with_capacity(jobs.len());
        for (k, pose) in a.iter().enumerate() {
            poses.push(*pose);
            poses.extend(b.get(k));
        }
        Ok((rate, poses))
    };
    let points: Vec<&[[f64; 2]]> = jobs.iter().map(|(p, _)| p.as_slice()).collect();
    let guesses: Vec<Pose2> = jobs.iter().map(|(_, g)| g.compose(offset)).collect();
    let many = |threads: Option<usize>| -> Result<(f64, Vec<Pose2>), String> {
        let t = Instant::now();
        let res = grid
            .match_many(&points, &guesses, &options, None, threads)
            .map_err(|e| e.to_string())?;
        let rate = jobs.len() as f64 / t.elapsed().as_secs_f64();
        Ok((rate, res.iter().map(|m| m.pose).collect()))
    };
    run([&grid, &grid], false)?; // distributions built, caches warm
    let clone = grid.clone();
    for _ in 0..reps {
        let (one, p1) = run([&grid, &grid], false)?;
        let (shared, p2) = run([&grid, &grid], true)?;
        let (clones, p3) = run([&grid, &clone], true)?;
        let (many_one, p4) = many(Some(1))?;
        let (many_all, p5) = many(None)?;
        println!(
            "one {one:.0}/s, two on one grid {shared:.0}/s ({:.2}x), two on clones {clones:.0}/s ({:.2}x), \
             match_many one thread {many_one:.0}/s, every core {many_all:.0}/s ({:.2}x), same poses {}",
            shared / one,
            clones / one,
            many_all / many_one,
            p1 == p2 && p1 == p3 && p1 == p4 && p1 == p5
        );
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().collect();
    let usage =
        "usage: replay <dump> odometry [reps] [inline|loop-only|poses-only|no-filter] | matchhash | mapwork [reps] | threads [reps]";
    let (Some(path), Some(mode)) = (args.get(1), args.get(2)) else {
        return Err(usage.into());
    };
    let scans = read_dump(path)?;
    match mode.as_str() {
        "odometry" => odometry(
            &scans,
            args.get(3).map_or(Ok(1), |s| s.parse())?,
            match args.get(4).map(String::as_str) {
                None => None,
                Some(v @ ("inline" | "loop-only" | "poses-only" | "no-filter")) => Some(v),
                Some(_) => return Err(usage.into()),
            },
        ),
        "matchhash" => matchhash(&scans),
        "mapwork" => mapwork(&scans, args.get(3).map_or(Ok(3), |s| s.parse())?),
        "threads" => threads(&scans, args.get(3).map_or(Ok(7), |s| s.parse())?),
        _ => Err(usage.into()),
    }
}
