//! A set of cell keys that an update uses for its bookkeeping ("seen this
//! key already?") and keeps between calls, so that each call reuses its
//! capacity instead of allocating (and clearing) a fresh hash set. It holds
//! nothing between calls: a clone starts empty (with the same capacity).

use rustc_hash::FxHashSet;

use crate::key::CellKey;

/// A reusable set of keys (see the module docs).
#[derive(Debug, Default)]
pub(crate) struct KeyScratch(FxHashSet<CellKey>);

impl KeyScratch {
    /// The set, emptied (its capacity kept).
    pub(crate) fn take(&mut self) -> &mut FxHashSet<CellKey> {
        self.0.clear();
        &mut self.0
    }
}

/// Empty, as the scratch is between calls, with the original's capacity:
/// the first updates of a clone then run as the original's would, instead of
/// growing the set from nothing (a rehash at every doubling).
impl Clone for KeyScratch {
    fn clone(&self) -> Self {
        Self(FxHashSet::with_capacity_and_hasher(
            self.0.capacity(),
            Default::default(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clone_is_empty_with_the_capacity_of_the_original() {
        let mut scratch = KeyScratch::default();
        scratch
            .take()
            .extend((0..1000).map(|i| CellKey { ix: i, iy: -i }));
        let mut clone = scratch.clone();
        assert!(clone.0.is_empty());
        assert!(clone.0.capacity() >= 1000, "{}", clone.0.capacity());
        // Taking the original empties it and keeps its capacity.
        assert!(scratch.take().is_empty());
        assert!(clone.take().capacity() >= 1000);
    }
}
