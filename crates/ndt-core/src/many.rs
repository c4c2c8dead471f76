//! Many scans matched against one grid in one call ([`NdtGrid::match_many`]):
//! relocalisation from several hypotheses, loop-closure candidates, a log
//! re-matched against a finished map. Each scan's result is that of its own
//! [`NdtGrid::match_scan`] (or [`NdtGrid::match_phased`]) call, bit for bit,
//! whatever the number of threads: a scan is matched by one thread from
//! start to end, and the scans share nothing but the grid, which they only
//! read.
//!
//! The calling thread matches scans too, beside helper threads started for
//! the batch; each thread takes the next scan not yet taken (a counter), so
//! a slower core simply takes fewer. Helpers are started per batch rather
//! than woken from a pool: a new thread goes to the idlest core, whereas a
//! sleeping pool thread woken by a busy one may be put on the waker's core
//! and wait there for the scheduler's tick (seen on this project's VM with
//! rayon's pool: benches/SPEED_LOG.md, session 30). A helper costs about
//! 0.1 ms before its first scan is done, so a batch starts one only for
//! every [`MIN_SCANS_PER_THREAD`] scans.

use std::any::Any;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread;

use crate::error::{check_pose_count, in_scan, NdtError, Result};
use crate::grid::NdtGrid;
use crate::matcher::{check_phases, MatchOptions, MatchResult};
use crate::se2::Pose2;

impl NdtGrid {
    /// Matches `scans[i]` (scan-frame points \[m\]) from `guesses[i]`
    /// (`T_map_scan`) for every `i`, with `options`, or with the phased
    /// expansions `phases` when given ([`NdtGrid::match_phased`]); results
    /// in the order of the scans.
    ///
    /// `threads`: how many threads match: the calling thread and `threads −
    /// 1` helpers, at most one thread per two scans.
    /// `None`: one per CPU the calling thread may run on (as
    /// [`std::thread::available_parallelism`] counts them for it: its CPU
    /// affinity and the cgroup's quota; see the crate's `affinity` module), since the
    /// helpers inherit the caller's affinity; `Some(1)`: the calling thread
    /// alone. A helper the system refuses to start leaves its share to the
    /// others.
    ///
    /// Everything is checked before any scan is matched: the options, the
    /// number of guesses, and each scan as [`NdtGrid::match_scan`] checks
    /// it ([`NdtError::InScan`] names the first scan rejected). An empty
    /// batch gives an empty result.
    pub fn match_many(
        &self,
        scans: &[&[[f64; 2]]],
        guesses: &[Pose2],
        options: &MatchOptions,
        phases: Option<&[f64]>,
        threads: Option<usize>,
    ) -> Result<Vec<MatchResult>> {
        options.validate()?;
        if let Some(phases) = phases {
            check_phases(options, phases)?;
        }
        let levels = self.match_levels(options)?;
        if threads == Some(0) {
            return Err(NdtError::InvalidOption {
                name: "threads",
                expected: "at least 1 thread (or None: every core)",
                value: 0.0,
            });
        }
        check_pose_count("guesses", scans.len(), guesses.len())?;
        for (index, (points, guess)) in scans.iter().zip(guesses).enumerate() {
            self.check_scan(points, *guess).map_err(in_scan(index))?;
        }
        // Checked above: each scan is not checked again.
        let one = |i: usize| match phases {
            Some(phases) => self.phased_checked(scans[i], guesses[i], options, phases, levels),
            None => self.match_checked(scans[i], guesses[i], options, levels),
        };
        let threads = threads.unwrap_or_else(crate::affinity::threads_for_caller);
        let results = spread(scans.len(), threads, one)?;
        // Nothing fails once the inputs are checked; should a scan still
        // fail, the first one's error is the call's.
        results
            .into_iter()
            .enumerate()
            .map(|(index, r)| r.map_err(in_scan(index)))
            .collect()
    }
}

/// Fewest scans a thread of a batch is started for. A helper costs about
/// 0.1 ms before its first scan is done (starting it, and the grid's cells
/// read into its core's caches): batches of 1, 2 and 4 simulated 683-point
/// scans (about 0.1 ms each) on 2 cores ran at 0.74, 0.86 and 1.22× the
/// one-thread rate with a helper for any batch (and the cores asked on
/// every call), at 1.00, 0.99–1.01 and 1.45–1.51× with this bound and
/// the count of cores asked once (benches/SPEED_LOG.md, session 30; the
/// count now comes from [`crate::affinity::threads_for_caller`]).
const MIN_SCANS_PER_THREAD: usize = 2;

/// `f(0) … f(n − 1)` in order, computed by the calling thread and up to
/// `threads − 1` helper threads started here (at most one thread per
/// [`MIN_SCANS_PER_THREAD`] items), each taking the next index not yet
/// taken. A helper that cannot be started is done without; a helper's
/// panic becomes [`NdtError::ThreadPanicked`].
fn spread<T: Send>(n: usize, threads: usize, f: impl Fn(usize) -> T + Sync) -> Result<Vec<T>> {
    let next = AtomicUsize::new(0);
    let work = || {
        let mut done = Vec::new();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= n {
                return done;
            }
            done.push((i, f(i)));
        }
    };
    let helpers = threads.min(n / MIN_SCANS_PER_THREAD).saturating_sub(1);
    let mut all = thread::scope(|s| {
        let started: Vec<_> = (0..helpers)
            .filter_map(|_| {
                thread::Builder::new()
                    .name("ndtgrid-match".into())
                    .spawn_scoped(s, work)
                    .ok()
            })
            .collect();
        let mut all = work();
        // Every helper joined before any is reported: a scope with a
        // panicked helper not joined would panic itself.
        let mut failed = None;
        for h in started {
            match h.join() {
                Ok(done) => all.extend(done),
                Err(payload) => {
                    failed.get_or_insert(panic_error(payload));
                }
            }
        }
        failed.map_or(Ok(all), Err)
    })?;
    all.sort_unstable_by_key(|&(i, _)| i);
    Ok(all.into_iter().map(|(_, t)| t).collect())
}

/// A thread's panic payload as an error.
fn panic_error(payload: Box<dyn Any + Send>) -> NdtError {
    let reason = payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    NdtError::ThreadPanicked { reason }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::testing::{room_map, room_scan};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    fn batch(n: usize) -> (NdtGrid, Vec<Vec<[f64; 2]>>, Vec<Pose2>) {
        let mut rng = StdRng::seed_from_u64(5);
        let grid = room_map(&mut rng);
        let mut scans = Vec::new();
        let mut guesses = Vec::new();
        for i in 0..n {
            let truth = Pose2::new(
                rng.random_range(-0.3..0.3),
                rng.random_range(-0.3..0.3),
                rng.random_range(-0.1..0.1),
            );
            scans.push(room_scan(truth, &mut rng));
            let off = 0.02 + 0.01 * (i % 3) as f64;
            guesses.push(Pose2::new(truth.x + off, truth.y - off, truth.theta + 0.01));
        }
        (grid, scans, guesses)
    }

    fn views(scans: &[Vec<[f64; 2]>]) -> Vec<&[[f64; 2]]> {
        scans.iter().map(Vec::as_slice).collect()
    }

    /// One thread, the global pool and a pool of three give each scan the
    /// bits of its own `match_scan` (and `match_phased`) call, in order.
    #[test]
    fn same_bits_as_one_call_per_scan() {
        let (grid, scans, guesses) = batch(23);
        let options = MatchOptions::default();
        for phases in [None, Some([100.0, 10.0].as_slice())] {
            let want: Vec<MatchResult> = scans
                .iter()
                .zip(&guesses)
                .map(|(s, g)| match phases {
                    Some(p) => grid.match_phased(s, *g, &options, p).unwrap(),
                    None => grid.match_scan(s, *g, &options).unwrap(),
                })
                .collect();
            assert!(want.iter().all(|r| r.converged));
            for threads in [Some(1), None, Some(3)] {
                let got = grid
                    .match_many(&views(&scans), &guesses, &options, phases, threads)
                    .unwrap();
                assert_eq!(got, want, "threads {threads:?}, phases {phases:?}");
            }
        }
    }

    /// Every index once, in order, whatever the number of threads (more
    /// than items too); a helper's panic is an error, not a panic.
    #[test]
    #[allow(clippy::panic)]
    fn spread_keeps_order_and_reports_panics() {
        for threads in [1, 2, 5, 64] {
            let got = spread(37, threads, |i| (i, thread::current().id())).unwrap();
            assert_eq!(
                got.iter().map(|g| g.0).collect::<Vec<_>>(),
                (0..37).collect::<Vec<_>>()
            );
            let ids: std::collections::HashSet<_> = got.iter().map(|g| g.1).collect();
            assert!(ids.len() <= threads.min(37 / MIN_SCANS_PER_THREAD));
        }
        assert!(spread(0, 4, |i| i).unwrap().is_empty());
        // Fewer than two items per thread: the calling thread alone.
        let caller = thread::current().id();
        let small = spread(3, 8, |_| thread::current().id()).unwrap();
        assert_eq!(small, vec![caller; 3]);
        // Three helpers, each panicking on the first index it takes; the
        // calling thread waits (up to 10 s) until all three have panicked.
        let panicked = AtomicUsize::new(0);
        let err = spread(64, 4, |i| {
            if thread::current().id() != caller {
                panicked.fetch_add(1, Ordering::SeqCst);
                panic!("scan {i} failed");
            }
            for _ in 0..10_000 {
                if panicked.load(Ordering::SeqCst) == 3 {
                    break;
                }
                thread::sleep(std::time::Duration::from_millis(1));
            }
            i
        })
        .unwrap_err();
        assert!(
            err.to_string().starts_with(
                "internal error: a thread matching scans of the batch panicked: scan "
            ),
            "{err}"
        );
    }

    #[test]
    fn empty_batch_gives_nothing() {
        let (grid, _, _) = batch(0);
        let got = grid
            .match_many(&[], &[], &MatchOptions::default(), None, None)
            .unwrap();
        assert!(got.is_empty());
    }

    /// Bad input is refused before any scan is matched, with the first bad
    /// scan's index and the message `match_scan` gives for it.
    #[test]
    fn errors_name_the_scan() {
        let (grid, mut scans, mut guesses) = batch(4);
        let options = MatchOptions::default();
        let run = |scans: &[Vec<[f64; 2]>], guesses: &[Pose2], threads| {
            grid.match_many(&views(scans), guesses, &options, None, threads)
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            run(&scans, &guesses[..3], None),
            "guesses: expected 4 poses (one per scan), got 3"
        );
        assert_eq!(
            run(&scans, &guesses, Some(0)),
            "threads: expected at least 1 thread (or None: every core), got 0"
        );
        scans[2][7] = [f64::NAN, 0.0];
        scans[3].clear();
        assert_eq!(
            run(&scans, &guesses, None),
            "scan 2: points: expected finite values, got NaN at index 7"
        );
        scans[2][7] = [0.0, 0.0];
        assert_eq!(
            run(&scans, &guesses, None),
            "scan 3: points: expected at least one point, got 0"
        );
        scans[3].push([0.0, 0.0]);
        guesses[1].theta = f64::INFINITY;
        assert_eq!(
            run(&scans, &guesses, None),
            "scan 1: guess: expected finite values, got inf at index 2"
        );
        guesses[1].theta = 0.0;
        let bad = MatchOptions {
            levels: Some(9),
            ..options
        };
        let err = grid
            .match_many(&views(&scans), &guesses, &bad, None, None)
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "levels: expected between 1 and the grid's number of pyramid levels, got 9"
        );
        let err = grid
            .match_many(
                &views(&scans),
                &guesses,
                &options,
                Some(&[10.0, -1.0]),
                None,
            )
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "expansion: expected a finite value > 0, got -1"
        );
        let err = grid
            .match_many(&views(&scans), &guesses, &options, Some(&[]), None)
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "expansion_phases: expected at least one expansion, got 0"
        );
    }
}
