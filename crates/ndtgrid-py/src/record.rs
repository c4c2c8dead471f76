//! Frozen records that pickle by value (`MatchResult`, `OdometryStep`,
//! `SmallObject`): `record!` declares the struct with its attributes and,
//! from the one list of fields, the tuple pickle keeps and the two
//! conversions; the class's `__reduce__` and `_restore` go through
//! [`reduce`] and `from_state`.

use pyo3::prelude::*;

/// Declares `struct $name { fields }` (attributes kept, e.g. `#[pyclass]`,
/// `#[pyo3(get)]`), `type $state` = the fields' types in order, and
/// `$name::state` / `$name::from_state` between the two.
macro_rules! record {
    (
        $(#[$meta:meta])*
        pub struct $name:ident ($state:ident) {
            $( $(#[$fmeta:meta])* $field:ident : $t:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone)]
        pub struct $name {
            $( $(#[$fmeta])* $field: $t, )*
        }

        /// Every field, in declaration order: what pickle keeps.
        pub(crate) type $state = ( $( $t, )* );

        impl $name {
            /// The fields as pickle keeps them.
            pub(crate) fn state(&self) -> $state {
                ( $( self.$field.clone(), )* )
            }

            /// The record of `state`'s fields.
            pub(crate) fn from_state(state: $state) -> Self {
                let ( $( $field, )* ) = state;
                Self { $( $field, )* }
            }
        }
    };
}

/// What a record's `__reduce__` returns: its class's `_restore` and `state`.
pub(crate) fn reduce<'py, T: pyo3::PyClass, S>(
    slf: &Bound<'py, T>,
    state: S,
) -> PyResult<(Bound<'py, PyAny>, (S,))> {
    Ok((slf.as_any().get_type().getattr("_restore")?, (state,)))
}
