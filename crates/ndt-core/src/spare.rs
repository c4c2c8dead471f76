//! Copies that keep the original's spare capacity.
//!
//! A derived `Clone` of a `Vec` allocates exactly its length, so the first
//! push into a copy reallocates it and copies every element, and a scratch
//! vector emptied between updates comes back with no storage at all. A map's
//! copy is made to be changed (an insert into a copy of the map, a what-if
//! before a loop closure), so its storage is copied with the original's
//! capacity: its inserts then grow it as they would the original
//! (amortised), instead of each copy paying the growth again on its first
//! insert.

/// A copy of `v` with `v`'s capacity.
pub(crate) fn clone_vec<T: Clone>(v: &Vec<T>) -> Vec<T> {
    let mut copy = Vec::with_capacity(v.capacity());
    copy.extend_from_slice(v);
    copy
}

/// A copy of `v` whose vectors each keep their capacity.
pub(crate) fn clone_nested<T: Clone>(v: &Vec<Vec<T>>) -> Vec<Vec<T>> {
    let mut copy = Vec::with_capacity(v.capacity());
    copy.extend(v.iter().map(clone_vec));
    copy
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_keep_elements_and_capacity() {
        let mut v = Vec::with_capacity(10);
        v.extend([1u32, 2, 3]);
        let c = clone_vec(&v);
        assert_eq!(c, [1, 2, 3]);
        assert!(c.capacity() >= 10);

        let mut inner = Vec::with_capacity(7);
        inner.push(5u8);
        let mut outer = Vec::with_capacity(4);
        outer.extend([inner, Vec::new()]);
        let c = clone_nested(&outer);
        assert_eq!(c, [vec![5u8], vec![]]);
        assert!(c.capacity() >= 4);
        assert!(c[0].capacity() >= 7);
        assert_eq!(c[1].capacity(), 0);
    }
}
