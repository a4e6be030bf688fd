//! The FMU archive: a zip written byte-for-byte reproducibly (fixed entry order, timestamps of
//! 1980-01-01 00:00, fixed permissions, deflate level 6) and atomically (a temporary file in the
//! same directory, renamed over the target only when complete).

use crate::error::HarnessError;
use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

/// One file of the archive.
#[derive(Debug, Clone, Copy)]
pub struct Entry<'a> {
    /// Path inside the archive, `/`-separated.
    pub path: &'a str,
    pub data: &'a [u8],
    /// Unix permissions (0o644 for data, 0o755 for shared libraries).
    pub mode: u32,
}

/// The zip archive of the entries, in the order given.
pub fn zip_bytes(entries: &[Entry], origin: &Path) -> Result<Vec<u8>, HarnessError> {
    let zip_err = |source| HarnessError::Zip {
        path: origin.to_path_buf(),
        source,
    };
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    for e in entries {
        let options = SimpleFileOptions::default()
            .compression_method(CompressionMethod::Deflated)
            .compression_level(Some(6))
            .last_modified_time(DateTime::default())
            .unix_permissions(e.mode);
        zip.start_file(e.path, options).map_err(zip_err)?;
        zip.write_all(e.data)
            .map_err(|err| HarnessError::io(origin, "compressing into the archive", err))?;
    }
    Ok(zip.finish().map_err(zip_err)?.into_inner())
}

/// Writes the archive to `out`: to a temporary sibling first, then renamed; on any failure
/// nothing is left behind (an older file at `out` stays as it was).
pub fn write_fmu(out: &Path, entries: &[Entry]) -> Result<(), HarnessError> {
    let bytes = zip_bytes(entries, out)?;
    write_atomically(out, &bytes)
}

/// Writes `bytes` to `path` through a temporary file in the same directory and a rename.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), HarnessError> {
    if path.is_dir() || path.as_os_str().to_string_lossy().ends_with('/') {
        return Err(HarnessError::BadOutput {
            path: path.to_path_buf(),
        });
    }
    let name = path
        .file_name()
        .ok_or_else(|| HarnessError::BadOutput {
            path: path.to_path_buf(),
        })?
        .to_string_lossy()
        .into_owned();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir)
        .map_err(|e| HarnessError::io(&dir, "creating the output directory", e))?;
    let tmp = TempFile(dir.join(format!(".{name}.tmp-{}", std::process::id())));
    let write = || -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp.0)?;
        f.write_all(bytes)?;
        f.sync_all()
    };
    write().map_err(|e| HarnessError::io(&tmp.0, "writing the FMU", e))?;
    std::fs::rename(&tmp.0, path)
        .map_err(|e| HarnessError::io(path, "moving the FMU in place", e))?;
    std::mem::forget(tmp);
    Ok(())
}

/// A temporary file removed when dropped (that is, unless the write completed).
struct TempFile(PathBuf);

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}
