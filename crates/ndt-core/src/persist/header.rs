//! The fixed header in front of every saved map: magic bytes, kind, version,
//! payload length and a CRC-32 over header and payload (see [`super`]).

use crate::error::{NdtError, Result};

/// The first 8 bytes of every ndtgrid file.
pub const MAGIC: [u8; 8] = *b"NDTGRID\0";

/// The format version this build writes, and the only one it reads.
pub const VERSION: u32 = 1;

/// Length of the header, in bytes.
pub const HEADER_LEN: usize = 28;

/// Offset of the CRC-32: the bytes before it are the checksummed header.
const CRC_AT: usize = 24;

/// What a file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// An [`crate::NdtGrid`] (tag `GRID`).
    Grid,
    /// A [`crate::Mapper`]: grid and filter state (tag `MAPR`).
    Mapper,
}

impl FileKind {
    /// The 4-byte tag at offset 8.
    pub const fn tag(self) -> [u8; 4] {
        match self {
            FileKind::Grid => *b"GRID",
            FileKind::Mapper => *b"MAPR",
        }
    }

    /// The kind's name in messages: `"grid"` or `"mapper"`.
    pub const fn name(self) -> &'static str {
        match self {
            FileKind::Grid => "grid",
            FileKind::Mapper => "mapper",
        }
    }

    /// The kind of a tag, if it is one.
    pub fn from_tag(tag: [u8; 4]) -> Option<FileKind> {
        [FileKind::Grid, FileKind::Mapper]
            .into_iter()
            .find(|k| k.tag() == tag)
    }
}

/// The whole file: the header for a `kind` payload, then the payload.
pub fn seal(kind: FileKind, payload: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&kind.tag());
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    let crc = checksum(&out, payload);
    out.extend_from_slice(&crc.to_le_bytes());
    out.extend_from_slice(payload);
    out
}

/// CRC-32 (IEEE) of the header's first 24 bytes and the payload.
pub fn checksum(head: &[u8], payload: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(head);
    h.update(payload);
    h.finalize()
}

/// The payload of `bytes`, after checking magic, header length, version,
/// kind (`kind` expected), file length and checksum, in that order.
pub fn open(bytes: &[u8], kind: FileKind) -> Result<&[u8]> {
    let got = bytes.len() as u64;
    let n = bytes.len().min(MAGIC.len());
    if bytes[..n] != MAGIC[..n] {
        return Err(NdtError::NotNdtFile);
    }
    if bytes.len() < HEADER_LEN {
        return Err(NdtError::Truncated {
            expected: HEADER_LEN as u64,
            got,
        });
    }
    let version = u32::from_le_bytes(field(bytes, 12));
    if version != VERSION {
        return Err(NdtError::UnsupportedVersion {
            found: version,
            supported: VERSION,
        });
    }
    let tag: [u8; 4] = field(bytes, 8);
    match FileKind::from_tag(tag) {
        Some(k) if k == kind => {}
        found => {
            return Err(NdtError::WrongKind {
                expected: kind.name(),
                found: match found {
                    Some(k) => format!("a {} file", k.name()),
                    None => format!("an unknown kind tagged {}", tag.escape_ascii()),
                },
            })
        }
    }
    let length = u64::from_le_bytes(field(bytes, 16));
    let expected = length.saturating_add(HEADER_LEN as u64);
    if got < expected {
        return Err(NdtError::Truncated { expected, got });
    }
    if got > expected {
        return Err(NdtError::TrailingBytes { expected, got });
    }
    let stored = u32::from_le_bytes(field(bytes, CRC_AT));
    let payload = &bytes[HEADER_LEN..];
    let computed = checksum(&bytes[..CRC_AT], payload);
    if stored != computed {
        return Err(NdtError::ChecksumMismatch { stored, computed });
    }
    Ok(payload)
}

/// The `N` bytes at `at` (zeros past the end; callers check the length).
fn field<const N: usize>(bytes: &[u8], at: usize) -> [u8; N] {
    let mut out = [0u8; N];
    if let Some(src) = bytes.get(at..at + N) {
        out.copy_from_slice(src);
    }
    out
}
