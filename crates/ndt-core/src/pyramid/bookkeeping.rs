//! What one update of the [`super::Pyramid`] keeps track of: which cells
//! of a level it has met ([`Stamps`]) and the indices of the values it
//! changed ([`ChangedIndices`]), each kept between updates for its storage.

use crate::spare::{clone_nested, clone_vec};

/// Per level, the indices among the level's values of the cells the last
/// update changed, in the order of the keys it returned for the level, while
/// they hold: a new cell's value is pushed, so only a removal on that level
/// moves one. The distributions' update then reads each changed cell's new
/// sums without looking the cell up again.
#[derive(Debug, Default)]
pub(super) struct ChangedIndices {
    /// Per level (reused between updates).
    levels: Vec<Vec<u32>>,
    /// Per level: whether `levels` holds the last update's indices.
    valid: Vec<bool>,
}

impl ChangedIndices {
    /// Level `level`'s vector, emptied, for an update that fills it; the
    /// level counts as not indexed until [`ChangedIndices::done`].
    pub(super) fn start(&mut self, level: usize) -> Vec<u32> {
        if self.levels.len() <= level {
            self.levels.resize_with(level + 1, Vec::new);
            self.valid.resize(level + 1, false);
        }
        self.valid[level] = false;
        let mut v = std::mem::take(&mut self.levels[level]);
        v.clear();
        v
    }

    /// Puts back level `level`'s vector; `hold`: its indices are those of
    /// the update's changed cells.
    pub(super) fn done(&mut self, level: usize, indices: Vec<u32>, hold: bool) {
        if let (Some(l), Some(v)) = (self.levels.get_mut(level), self.valid.get_mut(level)) {
            *l = indices;
            *v = hold;
        }
    }

    /// Level `level` is not indexed by the last update.
    pub(super) fn forget(&mut self, level: usize) {
        if let Some(v) = self.valid.get_mut(level) {
            *v = false;
        }
    }

    /// Level `level`'s indices, if the last update gave them.
    pub(super) fn get(&self, level: usize) -> Option<&[u32]> {
        match self.valid.get(level) {
            Some(true) => self.levels.get(level).map(Vec::as_slice),
            _ => None,
        }
    }

    /// Bytes on the heap.
    pub(super) fn heap_bytes(&self) -> usize {
        self.levels.iter().map(|l| l.capacity() * 4).sum::<usize>() + self.valid.capacity()
    }
}

/// Which cells one update of a level ([`super::Pyramid::add_fine`],
/// [`super::Pyramid::refresh_parents`]) has met already: a mark per cell, compared
/// with the update's number, instead of a set of keys (one look-up finds the
/// cell's value and its mark, and the same index then takes its new sums
/// without a second look-up). The numbers are bytes: a byte a cell, and
/// every 255 updates all marks are cleared once, so that no old mark equals
/// a new number.
#[derive(Debug, Default)]
pub(super) struct Stamps {
    pub(super) call: u8,
    levels: Vec<Vec<u8>>,
}

impl Stamps {
    /// Starts a new update: no cell is met yet.
    pub(super) fn next_call(&mut self, levels: usize) {
        self.levels.resize_with(levels, Vec::new);
        self.call = self.call.wrapping_add(1);
        if self.call == 0 {
            for l in &mut self.levels {
                l.fill(0);
            }
            self.call = 1;
        }
    }

    /// Room for the marks of `len` values on level `level` (once per level
    /// and update, not per cell).
    pub(super) fn prepare(&mut self, level: usize, len: usize) {
        if let Some(marks) = self.levels.get_mut(level) {
            if marks.len() < len {
                marks.resize(len, 0);
            }
        }
    }

    /// Marks the cell of value index `index` on level `level` (prepared
    /// for it); `true` when this update had not met it.
    #[inline]
    pub(super) fn first_meeting(&mut self, level: usize, index: u32) -> bool {
        let Some(marks) = self.levels.get_mut(level) else {
            return true;
        };
        match marks.get_mut(index as usize) {
            // Written either way: no branch on whether it was met.
            Some(m) => {
                let first = *m != self.call;
                *m = self.call;
                first
            }
            None => true,
        }
    }

    /// Bytes on the heap.
    pub(super) fn heap_bytes(&self) -> usize {
        self.levels.iter().map(Vec::capacity).sum()
    }
}

/// A copy with the original's spare capacity ([`crate::spare`]).
impl Clone for ChangedIndices {
    fn clone(&self) -> Self {
        Self {
            levels: clone_nested(&self.levels),
            valid: clone_vec(&self.valid),
        }
    }
}

/// A copy with the original's spare capacity ([`crate::spare`]).
impl Clone for Stamps {
    fn clone(&self) -> Self {
        Self {
            call: self.call,
            levels: clone_nested(&self.levels),
        }
    }
}
