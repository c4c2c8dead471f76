//! Files on disk: whole reads, and atomic writes (temporary file in the
//! target's directory, written, synced, renamed over the target). Errors
//! name the file.

use std::io::Write;
use std::path::Path;

use crate::error::{NdtError, Result};

/// The bytes of the file at `path`.
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| io_error(path, "read the file", &e))
}

/// Writes `bytes` to `path` atomically: into a temporary file beside it
/// (same directory, so the rename cannot cross file systems), synced to
/// disk, then renamed over `path`. Readers see the old file or the new one,
/// whole; on any error `path` is untouched and the temporary file removed.
/// A new file gets the usual permissions (`0o666` less the umask).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let name = path
        .file_name()
        .ok_or_else(|| NdtError::Io {
            path: path.display().to_string(),
            action: "write the file",
            errno: None,
            message: "the path does not name a file".into(),
        })?
        .to_string_lossy();
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder
        .tempfile_in(dir)
        .map_err(|e| io_error(path, "create a temporary file beside it", &e))?;
    // From here on, dropping `tmp` on an error deletes the temporary file.
    tmp.write_all(bytes)
        .and_then(|()| tmp.as_file().sync_all())
        .map_err(|e| io_error(path, "write the file", &e))?;
    tmp.persist(path)
        .map_err(|e| io_error(path, "replace the file", &e.error))?;
    sync_dir(dir);
    Ok(())
}

/// Makes the rename durable (best effort: not every file system can sync a
/// directory, and the file itself is already whole on disk).
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// [`NdtError::Io`] for `path`: the operating system's description of the
/// error when there is one (without the "(os error N)" suffix, the number is
/// kept in `errno`; and without the temporary file's path that `tempfile`
/// adds), else the error's own message.
pub(crate) fn io_error(path: &Path, action: &'static str, e: &std::io::Error) -> NdtError {
    let errno = e.raw_os_error().or_else(|| wrapped_os_error(e));
    let message = match errno {
        Some(code) => {
            let text = std::io::Error::from_raw_os_error(code).to_string();
            let suffix = format!(" (os error {code})");
            text.strip_suffix(&suffix).unwrap_or(&text).to_string()
        }
        None => e.to_string(),
    };
    NdtError::Io {
        path: path.display().to_string(),
        action,
        errno,
        message,
    }
}

/// The error number of an OS error that `tempfile` wrapped with the
/// temporary file's path (its message reads "… (os error N) at path …").
fn wrapped_os_error(e: &std::io::Error) -> Option<i32> {
    let text = e.to_string();
    let start = text.find(" (os error ")? + " (os error ".len();
    let end = start + text.get(start..)?.find(')')?;
    text.get(start..end)?.parse().ok()
}

/// An error about the content of the file at `path` (I/O errors name the
/// file already).
pub(crate) fn in_file(path: &Path, error: NdtError) -> NdtError {
    match error {
        NdtError::Io { .. } | NdtError::InFile { .. } => error,
        other => NdtError::InFile {
            path: path.display().to_string(),
            error: Box::new(other),
        },
    }
}
