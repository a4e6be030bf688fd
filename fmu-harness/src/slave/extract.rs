//! Extracting an FMU the master does not trust (issue 35). Every entry is checked before a byte
//! is written: its name is a relative path that stays inside the extraction folder (no `..`, no
//! absolute path or drive, no NUL, at most [`MAX_NAME_BYTES`]), it is a file or a folder (a
//! symbolic link, FIFO or device is refused), the archive has at most [`MAX_ENTRIES`] entries
//! and declares at most [`MAX_EXTRACTED_BYTES`] in all. Then the bytes are counted as they are
//! inflated, since a header can lie: the copy stops one byte past the limit. Files are created
//! new (`create_new`: an entry given twice is refused) and only in folders this code made, so
//! nothing it writes can follow a link. The FMU's path itself must be a regular file, checked
//! without blocking before it is opened ([`crate::input_file::open`]: a FIFO would block).

use super::{FmuRefused, SlaveError};
use crate::platform::{FmiVersion, Platform};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Entries in one FMU (files and folders). Our FMUs have 6; large tool exports a few hundred.
pub const MAX_ENTRIES: usize = 10_000;
/// Bytes one FMU may expand to, all entries together: 512 MiB. Our FMUs expand to a few MB;
/// a 7.4 MB zip bomb to 4 GiB.
pub const MAX_EXTRACTED_BYTES: u64 = 512 * 1024 * 1024;
/// Bytes of one entry's name.
pub const MAX_NAME_BYTES: usize = 1024;

/// An entry's name as messages show it: escaped, and cut after 80 characters.
pub(crate) fn shown(name: &str) -> String {
    let mut s: String = name
        .chars()
        .take(80)
        .collect::<String>()
        .escape_debug()
        .collect();
    if name.chars().count() > 80 {
        s.push('…');
    }
    s
}

/// The relative path of an entry inside the extraction folder, or why it has none. Backslashes
/// count as separators (some Windows tools write them).
fn relative_path(name: &str) -> Result<PathBuf, &'static str> {
    if name.len() > MAX_NAME_BYTES {
        return Err("has a name longer than 1024 bytes");
    }
    if name.contains('\0') {
        return Err("has a NUL byte in its name");
    }
    let name = name.replace('\\', "/");
    let bytes = name.as_bytes();
    if name.starts_with('/') || (bytes.len() >= 2 && bytes[1] == b':') {
        return Err("is an absolute path");
    }
    let mut path = PathBuf::new();
    for part in name.split('/') {
        match part {
            "" | "." => {}
            ".." => return Err("climbs out of the FMU's folder (`..`)"),
            p => path.push(p),
        }
    }
    if path.as_os_str().is_empty() {
        return Err("has an empty name");
    }
    Ok(path)
}

/// What an entry is, from its Unix mode (file type bits 0o170000) and its name.
fn kind(mode: Option<u32>, name: &str) -> Result<bool, &'static str> {
    let is_dir = name.ends_with('/') || name.ends_with('\\');
    match (mode.map_or(0, |m| m & 0o170_000), is_dir) {
        (0 | 0o100_000, false) => Ok(false),
        (0 | 0o040_000, true) => Ok(true),
        (0o120_000, _) => Err("is a symbolic link"),
        (0o040_000 | 0o100_000, _) => Err("is a folder and a file at once"),
        (0o010_000, _) => Err("is a FIFO"),
        (0o020_000 | 0o060_000, _) => Err("is a device"),
        (0o140_000, _) => Err("is a socket"),
        _ => Err("has an unknown file type"),
    }
}

fn io(path: &Path, action: &'static str) -> impl FnOnce(std::io::Error) -> SlaveError {
    let path = path.to_path_buf();
    move |source| SlaveError::Io {
        path,
        action,
        source,
    }
}

/// The FMU archive at `fmu`, a regular file (checked without blocking), with at most
/// [`MAX_ENTRIES`] entries.
fn open_archive(fmu: &Path) -> Result<zip::ZipArchive<std::fs::File>, SlaveError> {
    let file = crate::input_file::open(fmu, "an FMU")?;
    let archive = zip::ZipArchive::new(file).map_err(|source| SlaveError::Zip {
        path: fmu.to_path_buf(),
        source,
    })?;
    if archive.len() > MAX_ENTRIES {
        return Err(SlaveError::from(FmuRefused::TooManyEntries {
            path: fmu.to_path_buf(),
            entries: archive.len(),
            limit: MAX_ENTRIES,
        }));
    }
    Ok(archive)
}

/// The bytes the entries of the FMU at `fmu` declare, all together (from its central
/// directory; nothing is inflated): what a co-simulation adds up before it extracts a unit.
pub fn declared_bytes(fmu: &Path) -> Result<u64, SlaveError> {
    let mut archive = open_archive(fmu)?;
    let mut declared: u64 = 0;
    for i in 0..archive.len() {
        let entry = archive.by_index_raw(i).map_err(|source| SlaveError::Zip {
            path: fmu.to_path_buf(),
            source,
        })?;
        declared = declared.saturating_add(entry.size());
    }
    Ok(declared)
}

/// Extracts `fmu` into `dir` (an empty folder this process made), or refuses it; at most
/// `budget` bytes (and never more than [`MAX_EXTRACTED_BYTES`]). Returns the bytes written.
pub(super) fn extract(fmu: &Path, dir: &Path, budget: u64) -> Result<u64, SlaveError> {
    let limit = budget.min(MAX_EXTRACTED_BYTES);
    let zip_err = |source| SlaveError::Zip {
        path: fmu.to_path_buf(),
        source,
    };
    let unsafe_entry = |name: &str, reason: &'static str| {
        SlaveError::from(FmuRefused::UnsafeEntry {
            path: fmu.to_path_buf(),
            entry: shown(name),
            reason,
        })
    };
    let too_large = |name: &str, bytes: u64, declared: bool| {
        SlaveError::from(FmuRefused::TooLarge {
            path: fmu.to_path_buf(),
            entry: shown(name),
            bytes,
            declared,
            limit,
        })
    };
    let mut archive = open_archive(fmu)?;
    // Every entry's name, kind and declared size first: nothing is written from an FMU that
    // would be refused for any of them.
    let mut plan: Vec<(PathBuf, bool)> = Vec::with_capacity(archive.len());
    let mut declared: u64 = 0;
    for i in 0..archive.len() {
        let entry = archive.by_index_raw(i).map_err(zip_err)?;
        let name = entry.name();
        let path = relative_path(name).map_err(|r| unsafe_entry(name, r))?;
        let is_dir = kind(entry.unix_mode(), name).map_err(|r| unsafe_entry(name, r))?;
        declared = declared.saturating_add(entry.size());
        if declared > limit {
            return Err(too_large(name, declared, true));
        }
        plan.push((path, is_dir));
    }
    let mut written: u64 = 0;
    for (i, (path, is_dir)) in plan.into_iter().enumerate() {
        let target = dir.join(&path);
        if is_dir {
            std::fs::create_dir_all(&target).map_err(io(&target, "creating a folder"))?;
            continue;
        }
        if let Some(parent) = target.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent, "creating a folder"))?;
        }
        let mut entry = archive.by_index(i).map_err(zip_err)?;
        let mut options = std::fs::OpenOptions::new();
        options.write(true).create_new(true);
        #[cfg(unix)]
        {
            use std::os::unix::fs::OpenOptionsExt;
            // Owner read/write always; execute and the group/other bits as the entry says.
            options.mode(entry.unix_mode().map_or(0o644, |m| (m & 0o755) | 0o600));
        }
        let mut out = options.open(&target).map_err(|source| {
            if source.kind() == std::io::ErrorKind::AlreadyExists {
                unsafe_entry(entry.name(), "comes twice")
            } else {
                io(&target, "creating a file")(source)
            }
        })?;
        let budget = limit - written;
        let copied =
            std::io::copy(&mut (&mut entry).take(budget + 1), &mut out).map_err(|source| {
                SlaveError::from(FmuRefused::Entry {
                    path: fmu.to_path_buf(),
                    entry: shown(entry.name()),
                    source,
                })
            })?;
        written += copied;
        if copied > budget {
            return Err(too_large(entry.name(), written, false));
        }
    }
    Ok(written)
}

/// Where the model's binary must be: a regular file (not a link) inside `dir`.
pub(super) fn binary_inside(dir: &Path, library: &Path) -> Result<(), SlaveError> {
    let refuse = |reason: &'static str| {
        SlaveError::from(FmuRefused::Binary {
            path: library.to_path_buf(),
            reason,
        })
    };
    let meta = std::fs::symlink_metadata(library).map_err(|_| refuse("is not in the FMU"))?;
    if !meta.file_type().is_file() {
        return Err(refuse("is not a regular file"));
    }
    let inside = match (dir.canonicalize(), library.canonicalize()) {
        (Ok(d), Ok(l)) => l.starts_with(d),
        _ => false,
    };
    if !inside {
        return Err(refuse("lies outside the FMU's extraction folder"));
    }
    Ok(())
}

/// The co-simulation entry points a binary of `version` must export for the master to load it;
/// the other functions it calls are looked up after loading ([`crate::fmi2_binding::Api::load`],
/// [`crate::fmi3_binding::Api::load`]).
fn entry_points(version: FmiVersion) -> [&'static str; 3] {
    match version {
        FmiVersion::V2 => ["fmi2Instantiate", "fmi2DoStep", "fmi2FreeInstance"],
        FmiVersion::V3 => [
            "fmi3InstantiateCoSimulation",
            "fmi3DoStep",
            "fmi3FreeInstance",
        ],
    }
}

/// The model's binary, read before it is loaded: at most
/// [`crate::engine_library::MAX_LIBRARY_BYTES`], a shared library of the platform this master
/// runs on ([`Platform::HOST`]: ELF x86-64 on Linux, PE32+ AMD64 DLL on Windows, from its
/// header) that exports the [`entry_points`] of its FMI `version` (its symbol table, read with the `object` crate). A file of
/// another kind is refused here, not handed to the system's loader.
pub(super) fn binary_loadable(library: &Path, version: FmiVersion) -> Result<(), SlaveError> {
    let refuse = |reason: &'static str| {
        SlaveError::from(FmuRefused::Binary {
            path: library.to_path_buf(),
            reason,
        })
    };
    let bytes = crate::engine_library::read(library)
        .map_err(|_| refuse("cannot be read or is larger than 256 MiB"))?;
    let kind = crate::platform::Platform::of_library(&bytes);
    let Some(kind) = kind.filter(|&k| k == Platform::HOST) else {
        return Err(refuse(
            "is not a 64-bit shared library of this platform (by its header)",
        ));
    };
    let missing = crate::engine_library::missing_functions_of(&bytes, kind, version)
        .map_err(|_| refuse("has a symbol table that cannot be read"))?;
    if missing.iter().any(|f| entry_points(version).contains(f)) {
        return Err(refuse(match version {
            FmiVersion::V2 => "does not export fmi2Instantiate, fmi2DoStep and fmi2FreeInstance",
            FmiVersion::V3 => {
                "does not export fmi3InstantiateCoSimulation, fmi3DoStep and fmi3FreeInstance"
            }
        }));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_leave_the_folder_are_refused() {
        assert_eq!(
            relative_path("binaries/linux64/m.so"),
            Ok(PathBuf::from("binaries/linux64/m.so"))
        );
        assert_eq!(
            relative_path("resources\\a.txt"),
            Ok(PathBuf::from("resources/a.txt"))
        );
        for bad in [
            "../x",
            "a/../../x",
            "/etc/passwd",
            "\\x",
            "C:/x",
            "a/..",
            "",
            "./",
            "a\0b",
        ] {
            assert!(relative_path(bad).is_err(), "{bad:?}");
        }
        assert!(relative_path(&"a".repeat(1025)).is_err());
    }

    #[test]
    fn only_files_and_folders_are_extracted() {
        assert_eq!(kind(None, "a"), Ok(false));
        assert_eq!(kind(Some(0o100_644), "a"), Ok(false));
        assert_eq!(kind(Some(0o040_755), "a/"), Ok(true));
        assert_eq!(kind(Some(0o755), "a/"), Ok(true));
        assert!(kind(Some(0o120_777), "a").is_err());
        assert!(kind(Some(0o010_644), "a").is_err());
        assert!(kind(Some(0o040_755), "a").is_err());
    }

    #[test]
    fn shown_names_are_escaped_and_cut() {
        assert_eq!(shown("a\nb"), "a\\nb");
        assert_eq!(shown(&"x".repeat(100)).chars().count(), 81);
    }
}
