//! What handing work to a sleeping thread and waiting for it costs on this
//! machine: the reason the odometry's mapper helper takes scans in batches
//! and the loop never waits for it per scan (`src/mapworker.rs`).
//!
//! `cargo run --release -p ndt-core --example handoff`: per round, the loop
//! does `gap` µs of its own work (the helper falls asleep), then sends the
//! helper `theirs` µs of work, does `mine` µs itself and waits for the
//! helper's answer. Prints the time per round against the ideal
//! `max(mine, theirs)`.

use std::error::Error;
use std::sync::mpsc::{channel, sync_channel};
use std::time::{Duration, Instant};

fn spin(d: Duration) {
    let t = Instant::now();
    while t.elapsed() < d {
        std::hint::spin_loop();
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let (tx, rx) = sync_channel::<u64>(1);
    let (done_tx, done_rx) = channel::<u64>();
    let helper = std::thread::spawn(move || {
        for w in rx {
            spin(Duration::from_micros(w));
            if done_tx.send(w).is_err() {
                break;
            }
        }
    });
    for (mine, theirs, gap) in [(0u64, 0u64, 300u64), (50, 50, 300), (80, 100, 300)] {
        let rounds = 2000;
        let mut total = Duration::ZERO;
        for _ in 0..rounds {
            spin(Duration::from_micros(gap));
            let t = Instant::now();
            tx.send(theirs)?;
            spin(Duration::from_micros(mine));
            done_rx.recv()?;
            total += t.elapsed();
        }
        println!(
            "mine {mine} us, theirs {theirs} us: {:.1} us a round (ideal {})",
            total.as_secs_f64() * 1e6 / f64::from(rounds),
            mine.max(theirs)
        );
    }
    drop(tx);
    helper.join().map_err(|_| "the helper panicked")?;
    Ok(())
}
