//! Score terms of one pyramid level already computed at a pose, kept for
//! reuse within one match.
//!
//! A coarse-to-fine stage sums its own level and the next coarser one
//! (`crate::matcher::LEVEL_WINDOW`), and starts where the previous stage
//! ended: the coarser level's terms at that pose are the ones the previous
//! stage computed last. Reusing them saves one pass over the scan per stage,
//! and changes no bit (the same sums, taken from where they were computed).

use nalgebra::Matrix3;

use crate::batch::PassTerms;
use crate::score::Order;
use crate::se2::Pose2;

/// Entries kept: a stage's last few evaluations (its final pose need not be
/// the last one evaluated: rejected line-search trials come after it).
const CAPACITY: usize = 8;

/// One evaluation: level, pose, order and terms.
type Entry = (usize, Pose2, Order, PassTerms);

/// The last few (8) evaluations of whole-scan score terms, by level, held
/// in place (a vector of them, grown in each match, took the allocator's
/// lock: benches/SPEED_LOG.md, session 27).
#[derive(Debug)]
pub struct LevelMemo {
    /// Filled in order, then each next one replaces the oldest.
    entries: [Option<Entry>; CAPACITY],
    next: usize,
}

impl Default for LevelMemo {
    fn default() -> Self {
        Self {
            entries: [None; CAPACITY],
            next: 0,
        }
    }
}

impl LevelMemo {
    /// The terms of `level` at exactly `pose`, if computed with at least
    /// `order` (derivatives include the value).
    pub fn get(&self, level: usize, pose: Pose2, order: Order) -> Option<PassTerms> {
        self.entries
            .iter()
            .flatten()
            .find(|(l, p, o, _)| {
                *l == level && *p == pose && (*o == order || *o == Order::Derivatives)
            })
            .map(|e| e.3)
    }

    /// The point-to-plane information of `level`'s own-cell pairs at exactly
    /// `pose` ([`PassTerms::information`]), if a pass with derivatives
    /// computed it there. A stage's frozen directions are those of its
    /// coarser level at its start, where the stage before ended.
    pub fn information(&self, level: usize, pose: Pose2) -> Option<Matrix3<f64>> {
        self.get(level, pose, Order::Derivatives)
            .map(|t| t.information)
    }

    /// Records the terms of `level` at `pose`.
    pub fn put(&mut self, level: usize, pose: Pose2, order: Order, terms: PassTerms) {
        if let Some(e) = self.entries.get_mut(self.next) {
            *e = Some((level, pose, order, terms));
        }
        self.next = (self.next + 1) % CAPACITY;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::score::ScoreTerms;

    fn terms(score: f64) -> PassTerms {
        PassTerms {
            terms: ScoreTerms {
                score,
                ..ScoreTerms::default()
            },
            information: Matrix3::identity() * score,
        }
    }

    #[test]
    fn finds_exact_pose_and_level_only() {
        let mut m = LevelMemo::default();
        let p = Pose2::new(0.1, 0.2, 0.3);
        m.put(2, p, Order::Value, terms(1.0));
        assert_eq!(m.get(2, p, Order::Value).map(|t| t.terms.score), Some(1.0));
        // Information comes from passes with derivatives only.
        assert!(m.information(2, p).is_none());
        // Value terms cannot stand in for derivatives.
        assert!(m.get(2, p, Order::Derivatives).is_none());
        assert!(m.get(1, p, Order::Value).is_none());
        assert!(m
            .get(2, Pose2::new(0.1, 0.2, 0.3 + 1e-15), Order::Value)
            .is_none());
        m.put(2, p, Order::Derivatives, terms(2.0));
        assert_eq!(
            m.get(2, p, Order::Derivatives).map(|t| t.terms.score),
            Some(2.0)
        );
        assert_eq!(m.information(2, p), Some(Matrix3::identity() * 2.0));
    }

    #[test]
    fn forgets_the_oldest_beyond_capacity() {
        let mut m = LevelMemo::default();
        for i in 0..=CAPACITY {
            m.put(
                0,
                Pose2::new(i as f64, 0.0, 0.0),
                Order::Value,
                terms(i as f64),
            );
        }
        assert!(m.get(0, Pose2::new(0.0, 0.0, 0.0), Order::Value).is_none());
        for i in 1..=CAPACITY {
            let p = Pose2::new(i as f64, 0.0, 0.0);
            assert_eq!(
                m.get(0, p, Order::Value).map(|t| t.terms.score),
                Some(i as f64)
            );
        }
    }
}
