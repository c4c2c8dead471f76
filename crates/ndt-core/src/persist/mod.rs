//! Saving and loading maps: a versioned, checksummed binary file, the same
//! bytes that the Python binding pickles.
//!
//! A file is a fixed 28-byte [`header`] followed by a payload:
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic bytes `NDTGRID\0` ([`MAGIC`]) |
//! | 8 | 4 | kind tag: `GRID` or `MAPR` ([`FileKind`]) |
//! | 12 | 4 | format version, little-endian `u32` ([`VERSION`]) |
//! | 16 | 8 | payload length in bytes, little-endian `u64` |
//! | 24 | 4 | CRC-32 (IEEE) of bytes 0..24 and the payload, little-endian `u32` |
//! | 28 | n | payload: the [`wire`] structures in `postcard` encoding |
//!
//! The payload of a grid holds its cell size, its number of pyramid levels
//! and every fine cell's exact state ([`crate::NdtGrid::cell_states`]: the
//! eq. (6) sums about the cell's centre, `f64` bits as they are); the coarser
//! levels and the distributions are rebuilt from them, bit for bit. A
//! mapper's payload holds its grid and the whole state of its
//! [`crate::MapFilter`] (options, per-cell records, scan and removal
//! counters), so that a loaded mapper goes on exactly as the saved one would.
//! The bytes are deterministic: the same map always gives the same file.
//!
//! Loading checks, in this order, the magic bytes, the header's length, the
//! version, the kind, the file's length, the checksum, the payload's
//! decoding (all of it, nothing left over) and finally the content (cell
//! sums, options, filter records, as `from_cell_states` and
//! [`crate::MapFilter::from_state`] do); each failure is its own
//! [`crate::NdtError`]. No input makes it panic.
//!
//! **Versioning.** The first 16 bytes (magic, kind, version) keep their
//! place in every version; everything after them belongs to the version.
//! Any change of the payload's layout or meaning bumps [`VERSION`] and adds a
//! new set of [`wire`] structures beside the old ones, which stay frozen so
//! that a newer build still reads older files. A build refuses versions it
//! does not know (in particular newer ones) and writes only the newest.
//!
//! **Atomicity.** [`write_atomic`] writes to a temporary file in the target's
//! directory, syncs it to disk and renames it over the target, so that the
//! target holds either the old or the new file, whole, even after a crash;
//! on error the temporary file is removed.

mod file;
mod grid;
pub mod header;
mod mapper;
pub mod wire;

pub use file::{read_file, write_atomic};
pub use header::{FileKind, HEADER_LEN, MAGIC, VERSION};
pub use mapper::{load_mapper_parts, mapper_from_bytes, mapper_to_bytes};
