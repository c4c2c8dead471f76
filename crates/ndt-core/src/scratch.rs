//! A set of cell keys that an update uses for its bookkeeping ("seen this
//! key already?") and keeps between calls, so that each call reuses its
//! capacity instead of allocating (and clearing) a fresh hash set. It holds
//! nothing between calls: a clone starts empty and two are always equal.

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

/// Empty: the scratch holds nothing between calls.
impl Clone for KeyScratch {
    fn clone(&self) -> Self {
        Self::default()
    }
}
