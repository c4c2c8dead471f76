//! [`Mapper`] to and from bytes and files (see [`super`] for the format),
//! and the same for a grid and filter state kept apart (as the Python
//! binding keeps them).

use std::path::Path;

use super::file::{in_file, read_file, write_atomic};
use super::header::{open, seal, FileKind};
use super::wire::{decode, encode, FilterV1, GridV1, MapperV1};
use crate::error::Result;
use crate::grid::NdtGrid;
use crate::mapper::{MapFilter, Mapper};

/// A mapper file's bytes for `grid` and the filter state `filter`.
pub fn mapper_to_bytes(grid: &NdtGrid, filter: &MapFilter) -> Result<Vec<u8>> {
    let wire = MapperV1 {
        grid: GridV1::of(grid),
        filter: FilterV1::of(filter),
    };
    Ok(seal(FileKind::Mapper, &encode(&wire)?))
}

/// The grid and filter state of a mapper file's bytes, validated.
pub fn mapper_from_bytes(bytes: &[u8]) -> Result<(NdtGrid, MapFilter)> {
    let wire: MapperV1 = decode(open(bytes, FileKind::Mapper)?)?;
    Ok((wire.grid.build()?, wire.filter.build()?))
}

/// The grid and filter state of the mapper file `path`. Errors name the
/// file.
pub fn load_mapper_parts(path: &Path) -> Result<(NdtGrid, MapFilter)> {
    mapper_from_bytes(&read_file(path)?).map_err(|e| in_file(path, e))
}

impl Mapper {
    /// The mapper as a mapper file's bytes: its grid and its whole filter
    /// state (deterministic: equal mappers give equal bytes).
    pub fn to_bytes(&self) -> Result<Vec<u8>> {
        mapper_to_bytes(self.grid(), self.filter())
    }

    /// The mapper of a mapper file's bytes: inserting the same scans into it
    /// and into the saved one gives the same maps, bit for bit.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let (grid, filter) = mapper_from_bytes(bytes)?;
        Ok(Mapper::from_parts(grid, filter))
    }

    /// Saves the mapper to the file `path`, atomically (see
    /// [`super::write_atomic`]).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        write_atomic(path.as_ref(), &self.to_bytes()?)
    }

    /// Loads a mapper saved by [`Mapper::save`]. Errors name the file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let (grid, filter) = load_mapper_parts(path.as_ref())?;
        Ok(Mapper::from_parts(grid, filter))
    }
}
