//! Concurrent readers of one grid (issue 6): `match_scan` takes `&self` and
//! prepares distributions lazily into a shared, bounded cache. Four threads
//! matching with 26 distinct option sets (more than the cache holds, so
//! entries are built, evicted and rebuilt while others read) get exactly the
//! results of the same matches run one by one on a fresh copy of the grid.

mod common;

use ndt_core::{MatchOptions, MatchResult, NdtGrid, Pose2};

/// Option sets: more than the grid's cache of prepared distributions (24).
const SETS: usize = 26;

fn options(i: usize) -> MatchOptions {
    MatchOptions {
        expansion: 2.0 + i as f64,
        fuse_minority: i.is_multiple_of(2),
        levels: Some(1),
        rotation_search: 0.0,
        ..MatchOptions::default()
    }
}

#[test]
fn concurrent_matches_equal_serial_matches_bit_for_bit() {
    let walls = common::room();
    let mut grid = NdtGrid::new(0.02).unwrap_or_else(|e| panic!("{e}"));
    for (k, p) in [Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.3, -0.2, 0.8)]
        .into_iter()
        .enumerate()
    {
        grid.insert(&common::urg_scan(&walls, p, 0.005, k as u64), p)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    let probe = common::scan(&walls, Pose2::new(0.05, 0.02, 0.1), 90, 3.0, 0.005, 9);
    let guess = Pose2::new(0.0, 0.0, 0.08);
    let reference: Vec<MatchResult> = (0..SETS)
        .map(|i| {
            let fresh = grid.clone();
            fresh
                .match_scan(&probe, guess, &options(i))
                .unwrap_or_else(|e| panic!("{e}"))
        })
        .collect();
    let shared = &grid;
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|t| {
                let (probe, reference) = (&probe, &reference);
                s.spawn(move || {
                    for round in 0..1 {
                        for j in 0..SETS {
                            let i = (j * 7 + t * 11 + round) % SETS;
                            let r = shared
                                .match_scan(probe, guess, &options(i))
                                .unwrap_or_else(|e| panic!("{e}"));
                            assert_eq!(r, reference[i], "thread {t}, options {i}");
                        }
                    }
                })
            })
            .collect();
        for h in handles {
            assert!(h.join().is_ok(), "a matcher thread panicked");
        }
    });
}
