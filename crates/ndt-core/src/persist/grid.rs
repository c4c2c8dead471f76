//! [`NdtGrid`] to and from bytes and files (see [`super`] for the format).

use std::path::Path;

use super::file::{in_file, read_file, write_atomic};
use super::header::{open, seal, FileKind};
use super::wire::{decode, encode, GridV1};
use crate::error::Result;
use crate::grid::NdtGrid;

impl NdtGrid {
    /// The grid as a grid file's bytes (header and payload; deterministic:
    /// equal grids give equal bytes).
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        Ok(seal(FileKind::Grid, &encode(&GridV1::of(self))?))
    }

    /// The grid of a grid file's bytes, bit for bit the one saved
    /// ([`NdtGrid::cell_states`], levels, cell size). Errors on anything
    /// else (see [`super`] for what is checked).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        decode::<GridV1>(open(bytes, FileKind::Grid)?)?.build()
    }

    /// Saves the grid to the file `path`, atomically (see
    /// [`super::write_atomic`]).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        write_atomic(path.as_ref(), &self.to_bytes()?)
    }

    /// Loads a grid saved by [`NdtGrid::save`]. Errors name the file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_bytes(&read_file(path)?).map_err(|e| in_file(path, e))
    }
}
