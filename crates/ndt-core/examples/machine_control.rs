//! Timing control: fixed work that does not depend on this library, to run
//! beside a timed harness (`insert_case`) and tell the machine's spells from
//! a change of the code.
//!
//! `machine_control` prints, on one line, the time of
//! - a latency-bound integer chain (each step waits for the last: 20 M
//!   xorshift steps),
//! - eight independent chains (the same steps, eight at a time: as much work
//!   per cycle as the core allows),
//! - a pointer chase per working-set size (16 KiB to 256 MiB, one node per
//!   64-byte line in a random cycle): the latency of one load from L1, L2,
//!   L3 and memory.
//!
//! benches/SPEED_LOG.md, session 41, used it to show that the Zen 4 VM's
//! slow spells leave the latency-bound chain as it is.

use std::hint::black_box;
use std::time::Instant;

#[path = "common/controls.rs"]
mod controls;
use controls::{chase_cycle, step};

/// Milliseconds of 20 M dependent steps.
fn chain() -> f64 {
    let t = Instant::now();
    let mut x = black_box(88_172_645_463_325_252_u64);
    for _ in 0..20_000_000 {
        x = step(x);
    }
    black_box(x);
    t.elapsed().as_secs_f64() * 1e3
}

/// Milliseconds of 10 M rounds of eight independent steps.
fn chains8() -> f64 {
    let t = Instant::now();
    let mut x = black_box([1_u64, 2, 3, 4, 5, 6, 7, 8].map(|v| v * 0x9E37_79B9_7F4A_7C15));
    for _ in 0..10_000_000 {
        x = x.map(step);
    }
    black_box(x);
    t.elapsed().as_secs_f64() * 1e3
}

/// Nanoseconds per load of a chase through `bytes` of memory: one node per
/// 64-byte line, the nodes in one random cycle (Sattolo's shuffle).
fn chase(bytes: usize) -> f64 {
    let next = chase_cycle(bytes);
    let n = next.len() / controls::WORDS_PER_LINE;
    let load = |at: usize| next.get(at).copied().unwrap_or(0);
    // Once round the cycle to warm it, then timed.
    let mut at = 0;
    for _ in 0..n {
        at = load(at);
    }
    const LOADS: u32 = 2_000_000;
    let t = Instant::now();
    for _ in 0..LOADS {
        at = load(at);
    }
    black_box(at);
    t.elapsed().as_secs_f64() * 1e9 / f64::from(LOADS)
}

fn main() {
    let (one, eight) = (chain(), chains8());
    let loads: Vec<String> = [
        ("16K", 16 << 10),
        ("512K", 512 << 10),
        ("4M", 4 << 20),
        ("16M", 16 << 20),
        ("256M", 256 << 20),
    ]
    .iter()
    .map(|&(name, bytes)| format!("{name} {:.1}", chase(bytes)))
    .collect();
    println!(
        "chain {one:.1} ms, 8 chains {eight:.1} ms; load [ns]: {}",
        loads.join(", ")
    );
}
