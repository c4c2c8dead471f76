//! How many threads a batch may keep busy when its caller names no number
//! ([`crate::grid::NdtGrid::match_many`] with `threads: None`): one per CPU
//! the calling thread may run on.
//!
//! A thread started on Linux inherits the CPU affinity of the thread that
//! starts it, so a batch's helpers run on the CPUs its caller may run on.
//! [`std::thread::available_parallelism`] answers for the calling thread
//! (its affinity, and the cgroup's CPU quota), but it reads the cgroup's
//! files: about 26 µs a call on this project's VM, 40 % of a 683-point
//! match. The count used to be asked once per process, so a batch called
//! from a thread pinned to one CPU (as `README.md` tells users to pin their
//! matching threads) after one from an unpinned thread started a helper on
//! that same CPU: 0.97× the one-thread rate in 30 rounds (benches/SPEED_LOG.md,
//! session 33). Now the calling thread's affinity is read on every
//! call (one system call) and `available_parallelism` only when its answer
//! cannot follow from the last one's.

use std::sync::{Mutex, OnceLock, PoisonError};
use std::thread;

/// The CPUs the calling thread may run on (its affinity mask), or `None`
/// where that cannot be read (not Linux, or more CPUs than a mask holds).
#[cfg(target_os = "linux")]
pub(crate) fn caller_cpus() -> Option<usize> {
    use nix::sched::sched_getaffinity;
    use nix::unistd::Pid;
    // Pid 0: the calling thread.
    let set = sched_getaffinity(Pid::from_raw(0)).ok()?;
    let n = cpus_in(&set);
    (n > 0).then_some(n)
}

/// The CPUs set in an affinity mask.
#[cfg(target_os = "linux")]
fn cpus_in(set: &nix::sched::CpuSet) -> usize {
    (0..nix::sched::CpuSet::count())
        .filter(|&cpu| set.is_set(cpu).unwrap_or(false))
        .count()
}

/// The CPUs the calling thread may run on: unknown here.
#[cfg(not(target_os = "linux"))]
pub(crate) fn caller_cpus() -> Option<usize> {
    None
}

/// `available_parallelism`, at least 1.
fn parallelism() -> usize {
    thread::available_parallelism().map_or(1, usize::from)
}

/// Threads for a batch called on this thread: as
/// [`std::thread::available_parallelism`] would say now (the least of the
/// calling thread's CPUs and the cgroup's quota), asked only when the last
/// answer does not give it.
pub(crate) fn threads_for_caller() -> usize {
    let Some(mine) = caller_cpus() else {
        // No mask to go by: the process's answer, asked once.
        static ONCE: OnceLock<usize> = OnceLock::new();
        return *ONCE.get_or_init(parallelism);
    };
    if mine == 1 {
        return 1;
    }
    // The last answer of `available_parallelism` and the caller's CPUs then.
    static LAST: Mutex<Option<(usize, usize)>> = Mutex::new(None);
    let mut last = LAST.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(known) = from_last(mine, *last) {
        return known;
    }
    let answer = parallelism();
    *last = Some((mine, answer));
    answer
}

/// What `available_parallelism` = min(the caller's CPUs, the quota) says
/// for a caller of `mine` CPUs, given that it said `answer` to a caller of
/// `cpus` CPUs; `None` when that does not tell.
fn from_last(mine: usize, last: Option<(usize, usize)>) -> Option<usize> {
    let (cpus, answer) = last?;
    if answer < cpus {
        // The quota bound that answer: it is the quota.
        Some(mine.min(answer))
    } else if mine <= cpus {
        // The quota is at least `cpus`, so at least `mine`.
        Some(mine)
    } else {
        // The quota may lie between `cpus` and `mine`.
        None
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Against min(mine, quota) for every quota and pair of masks up to 8
    /// CPUs: each answer derived is right, and one is derived whenever the
    /// last answer bounds the quota enough.
    #[test]
    fn derived_answers_match_the_minimum() {
        for quota in 1..=8 {
            for cpus in 1..=8 {
                let last = Some((cpus, cpus.min(quota)));
                for mine in 1..=8 {
                    match from_last(mine, last) {
                        Some(n) => assert_eq!(n, mine.min(quota), "{quota} {cpus} {mine}"),
                        None => assert!(mine > cpus && quota >= cpus, "{quota} {cpus} {mine}"),
                    }
                }
            }
        }
        assert_eq!(from_last(3, None), None);
    }

    /// A thread pinned to one CPU gets 1 even after an unpinned thread
    /// asked (the count once cached for the process), and an unpinned
    /// thread after it gets `available_parallelism`'s answer again.
    #[cfg(target_os = "linux")]
    #[test]
    fn pinned_callers_get_their_own_count() {
        use nix::sched::{sched_getaffinity, sched_setaffinity, CpuSet};
        use nix::unistd::Pid;
        let full = parallelism();
        assert_eq!(threads_for_caller(), full);
        let mask = sched_getaffinity(Pid::from_raw(0)).unwrap();
        let first = (0..CpuSet::count())
            .find(|&c| mask.is_set(c).unwrap())
            .unwrap();
        let pinned = thread::spawn(move || {
            let mut one = CpuSet::new();
            one.set(first).unwrap();
            sched_setaffinity(Pid::from_raw(0), &one).unwrap();
            (caller_cpus(), threads_for_caller())
        })
        .join()
        .unwrap();
        assert_eq!(pinned, (Some(1), 1));
        assert_eq!(threads_for_caller(), full);
        assert_eq!(caller_cpus(), Some(cpus_in(&mask)));
    }
}
