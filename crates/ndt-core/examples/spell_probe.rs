//! Timing control: which kinds of work slow down in the machine's slow
//! spells, measured beside the insert itself.
//!
//! `spell_probe FILE [seconds]` reads the insert target's scans
//! (`benches/dump_insert_case.py`), then, for `seconds` (default 60), builds
//! a 2 cm map of the first 100 again and again and, as `insert_case` does,
//! matches (untimed) and inserts (timed) each next scan. After every insert
//! it times five small controls that do not depend on this library:
//! - `chain`: 20 k dependent xorshift steps (latency-bound arithmetic);
//! - `chains8`: 2 500 rounds of eight independent steps (throughput-bound);
//! - `branch`: 4 096 data-dependent branches in a fixed pattern;
//! - `loads`: 4 096 independent loads at random from a 512 KiB array (L2);
//! - `chase`: 2 000 dependent loads in a random cycle through 512 KiB.
//!
//! Each time is divided by the median of the same insert (the same scan into
//! the same map) or control over all rounds, and the ratios are taken in
//! windows of 30 consecutive inserts (about 5 ms). A window whose inserts
//! took 1.3× their usual time or more is slow; the program prints, for each
//! control, its median ratio in the slow windows and in the others.
//! benches/SPEED_LOG.md, session 48, used it to show that in the spells the
//! loads slow with the insert and the arithmetic does not.

use std::error::Error;
use std::hint::black_box;
use std::time::Instant;

use ndt_core::{MatchOptions, NdtGrid};

#[path = "common/controls.rs"]
mod controls;
#[path = "common/insert_scans.rs"]
mod insert_scans;
use controls::{chase_cycle, step};
use insert_scans::{median, scans, PREFILL};

/// What each round times: the insert and the five controls.
const NAMES: [&str; 6] = ["insert", "chain", "chains8", "branch", "loads", "chase"];
/// Inserts per window.
const WINDOW: usize = 30;
/// A window is slow when its inserts took this much their usual time.
const SLOW: f64 = 1.3;

#[inline(never)]
fn arm_a(x: u64) -> u64 {
    x.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(5)
}

#[inline(never)]
fn arm_b(x: u64) -> u64 {
    (x ^ (x >> 3)).wrapping_add(7)
}

/// One data-dependent branch per byte of `pattern` (the arms are calls, so
/// the compiler cannot turn the branch into a select).
#[inline(never)]
fn branchy(pattern: &[u8], mut x: u64) -> u64 {
    for &b in pattern {
        x = if b != 0 { arm_a(x) } else { arm_b(x) };
    }
    x
}

fn micros(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e6
}

/// The five controls' times \[µs\].
struct Controls {
    pattern: Vec<u8>,
    array: Vec<u64>,
    picks: Vec<usize>,
    next: Vec<usize>,
}

impl Controls {
    fn new() -> Self {
        let mut r = 12_345_u64;
        let mut draw = || {
            r = step(r);
            r >> 11
        };
        let pattern = (0..2048).map(|_| (draw() & 1) as u8).collect();
        let array = (0..65_536_u64).map(|i| i * 7).collect();
        let picks = (0..4096).map(|_| (draw() % 65_536) as usize).collect();
        Self {
            pattern,
            array,
            picks,
            next: chase_cycle(512 << 10),
        }
    }

    fn time(&self) -> [f64; 5] {
        let t = Instant::now();
        let mut x = black_box(88_u64);
        for _ in 0..20_000 {
            x = step(x);
        }
        black_box(x);
        let chain = micros(t);
        let t = Instant::now();
        let mut v = black_box([1_u64, 2, 3, 4, 5, 6, 7, 8]);
        for _ in 0..2500 {
            v = v.map(step);
        }
        black_box(v);
        let chains8 = micros(t);
        let t = Instant::now();
        black_box(branchy(black_box(&self.pattern), 1));
        black_box(branchy(black_box(&self.pattern), 2));
        let branch = micros(t);
        let t = Instant::now();
        let mut sum = 0_u64;
        for &i in black_box(&self.picks) {
            sum = sum.wrapping_add(self.array.get(i).copied().unwrap_or(0));
        }
        black_box(sum);
        let loads = micros(t);
        let t = Instant::now();
        let mut at = 0;
        for _ in 0..2000 {
            at = self.next.get(black_box(at)).copied().unwrap_or(0);
        }
        black_box(at);
        let chase = micros(t);
        [chain, chains8, branch, loads, chase]
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: spell_probe FILE [seconds]")?;
    let seconds: f64 = args.next().map_or(Ok(60.0), |s| s.parse())?;
    let scans = scans(&std::fs::read(path)?)?;
    let per_round = scans.len().saturating_sub(PREFILL);
    if per_round < WINDOW {
        return Err(format!("{} scans: need {} or more", scans.len(), PREFILL + WINDOW).into());
    }
    let controls = Controls::new();
    let options = MatchOptions::default();
    let start = Instant::now();
    // Per round, per scan: the insert's and the controls' times [µs].
    let mut rounds: Vec<Vec<[f64; 6]>> = Vec::new();
    while start.elapsed().as_secs_f64() < seconds {
        let mut grid = NdtGrid::new(0.02)?;
        for (points, pose) in &scans[..PREFILL] {
            grid.insert(points, *pose)?;
        }
        let mut round = Vec::with_capacity(per_round);
        for (points, pose) in &scans[PREFILL..] {
            grid.match_scan(points, *pose, &options)?;
            let t = Instant::now();
            grid.insert(points, *pose)?;
            let insert = micros(t);
            let [a, b, c, d, e] = controls.time();
            round.push([insert, a, b, c, d, e]);
        }
        rounds.push(round);
    }
    // The usual time of each insert and control: its median over the rounds.
    let usual: Vec<[f64; 6]> = (0..per_round)
        .map(|i| {
            std::array::from_fn(|k| {
                let mut v: Vec<f64> = rounds
                    .iter()
                    .filter_map(|r| r.get(i))
                    .map(|t| t[k])
                    .collect();
                median(&mut v)
            })
        })
        .collect();
    let ratios: Vec<[f64; 6]> = rounds
        .iter()
        .flat_map(|r| r.iter().zip(&usual))
        .map(|(t, u)| std::array::from_fn(|k| t[k] / u[k]))
        .collect();
    let windows: Vec<[f64; 6]> = ratios
        .chunks_exact(WINDOW)
        .map(|w| {
            std::array::from_fn(|k| {
                let mut v: Vec<f64> = w.iter().map(|t| t[k]).collect();
                median(&mut v)
            })
        })
        .collect();
    let (slow, quiet): (Vec<&[f64; 6]>, Vec<&[f64; 6]>) =
        windows.iter().partition(|w| w[0] >= SLOW);
    println!(
        "{} rounds of {per_round} inserts in {:.0} s; {} of {} windows of {WINDOW} inserts slow (inserts ≥ {SLOW}× their usual time)",
        rounds.len(),
        start.elapsed().as_secs_f64(),
        slow.len(),
        windows.len()
    );
    for (k, name) in NAMES.iter().enumerate() {
        let mut all: Vec<f64> = rounds.iter().flatten().map(|t| t[k]).collect();
        let mut s: Vec<f64> = slow.iter().map(|w| w[k]).collect();
        let mut q: Vec<f64> = quiet.iter().map(|w| w[k]).collect();
        println!(
            "{name:8} usual {:7.2} us; ratio in the slow windows {:.2}, in the others {:.2}",
            median(&mut all),
            median(&mut s),
            median(&mut q)
        );
    }
    Ok(())
}
