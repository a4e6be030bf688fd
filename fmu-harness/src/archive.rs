//! The FMU archive: a zip written byte-for-byte reproducibly (fixed entry order, timestamps of
//! 1980-01-01 00:00, fixed permissions, deflate level 6) and atomically (a temporary file in the
//! same directory, renamed over the target only when complete, and never over what is not a
//! regular file: [`crate::output_file`]).

use crate::error::HarnessError;
use std::io::{Cursor, Write};
use std::path::Path;
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

/// The writer of every output ([`crate::output_file::write_atomically`]), here where the FMU
/// archive first needed it.
pub use crate::output_file::write_atomically;
