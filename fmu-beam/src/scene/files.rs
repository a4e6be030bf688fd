//! Reading the files a scene names, as a receiver of scene files from others must (issues 35
//! and 45): one reader, [`read_below`], for every entry point (`Scene::load`, the Python
//! package's `Scene.from_dict` and `Scene.from_toml`, the command line). A named file is
//! refused without a look at the file system when its name leaves its base directory (an
//! absolute path, a `..` above the base); else it is resolved with its links followed and must
//! still lie below the base. It is read only if it is a regular file (its type checked before
//! it is opened, opened non-blocking, and checked again on the open handle: a FIFO or a device
//! would block or never end), and no further than a cap, enforced while reading. No refusal
//! quotes a byte of the file, says how long it is, or shows where a link leads: a name that
//! cannot be found, cannot be read or leads out through a link gets one message, so that a
//! refusal does not tell which files exist outside the base.

use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// Largest scene text read or parsed (bytes): a hand-written scene, or a packaged one with its
/// matrix files' texts inside. Shipped scenes are under 4 KiB.
pub const MAX_SCENE_BYTES: u64 = 4 << 20;
/// Largest matrix file read (bytes): the two 12 × 12 matrices at 17 digits take about 8 KiB,
/// so this leaves room for comments.
pub const MAX_MATRIX_FILE_BYTES: u64 = 64 << 10;

/// Why a named file was not read. The text of each variant is the rule a refusal names; none
/// carries a byte of the file, its size or a resolved path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FileRefusal {
    /// The name leaves the base directory by itself (absolute, empty, or a `..` above the
    /// base): refused before the file system is asked anything.
    #[error("must name a file below the scene's directory: a relative path, no `..` above it")]
    Outside,
    /// The name resolves to nothing readable below the base: it does not exist, a folder on
    /// the way cannot be searched, or a link leads out of the base. One message for all, so
    /// that it does not tell which of them.
    #[error(
        "names no file that can be read below the scene's directory (missing, not \
         readable, or a link that leads out of the directory)"
    )]
    Unreachable,
    /// Not a regular file (a directory, a FIFO, a device, a socket).
    #[error("must be a regular file; this is a {kind}")]
    NotRegular {
        /// What it is instead.
        kind: &'static str,
    },
    /// Larger than the cap (by its size, or found so while reading).
    #[error("must be at most {cap} bytes; it is larger")]
    TooLarge {
        /// The cap (bytes).
        cap: u64,
    },
    /// Not UTF-8 text.
    #[error("must be UTF-8 text, and is not")]
    NotText,
    /// The base directory itself cannot be resolved (the caller's own argument).
    #[error("its directory {dir} cannot be opened: {message}")]
    Base {
        /// The directory as the caller gave it.
        dir: String,
        /// The system's error.
        message: String,
    },
    /// The system refused a file named directly (no such file, permission, …).
    #[error("cannot be read: {message}")]
    Io {
        /// The system's error.
        message: String,
    },
}

fn io(e: std::io::Error) -> FileRefusal {
    FileRefusal::Io {
        message: e.to_string(),
    }
}

/// Whether `name`, taken relative to a directory, stays below it by its words alone: not
/// empty, not absolute, and no `..` climbs above the directory (a `.` or `a/..` that ends at
/// the directory itself does not name a file below it either).
fn lexically_below(name: &str) -> bool {
    let mut depth: usize = 0;
    for part in Path::new(name).components() {
        match part {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => match depth.checked_sub(1) {
                Some(d) => depth = d,
                None => return false,
            },
            Component::RootDir | Component::Prefix(_) => return false,
        }
    }
    depth > 0
}

/// `name` (as a scene wrote it) resolved below `dir` (the base directory), both with their
/// links followed; refused if its words leave `dir` ([`FileRefusal::Outside`]) or if it
/// resolves to nothing below `dir` ([`FileRefusal::Unreachable`]).
pub fn resolve_below(dir: &Path, name: &str) -> Result<PathBuf, FileRefusal> {
    if !lexically_below(name) {
        return Err(FileRefusal::Outside);
    }
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let base = dir.canonicalize().map_err(|e| FileRefusal::Base {
        dir: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let resolved = base
        .join(name)
        .canonicalize()
        .map_err(|_| FileRefusal::Unreachable)?;
    if resolved.starts_with(&base) && resolved != base {
        Ok(resolved)
    } else {
        Err(FileRefusal::Unreachable)
    }
}

/// The text of the file `name` names below `dir`, at most `cap` bytes: the one reader of the
/// files a scene names ([`resolve_below`], then [`read_capped`]).
pub fn read_below(dir: &Path, name: &str, cap: u64) -> Result<String, FileRefusal> {
    read_capped(&resolve_below(dir, name)?, cap)
}

/// What a file that is not regular is.
pub fn kind_of(t: std::fs::FileType) -> &'static str {
    if t.is_dir() {
        return "directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "FIFO";
        } else if t.is_char_device() {
            return "character device";
        } else if t.is_block_device() {
            return "block device";
        } else if t.is_socket() {
            return "socket";
        } else if t.is_symlink() {
            return "symbolic link";
        }
    }
    "special file"
}

/// The regular file at `path`, open for reading, of at most `cap` bytes by its size: its type
/// and size are checked before it is opened (a FIFO or a device is refused without being
/// opened), it is opened non-blocking, and checked again on the open handle (the path may
/// have been swapped in between). What every reader of a named file opens it with: this
/// module's readers, the harness's (`input_file`) and its FMU archives.
pub fn open_regular(path: &Path, cap: u64) -> Result<(std::fs::File, u64), FileRefusal> {
    let meta = std::fs::metadata(path).map_err(io)?;
    let check = |meta: &std::fs::Metadata| {
        if !meta.is_file() {
            return Err(FileRefusal::NotRegular {
                kind: kind_of(meta.file_type()),
            });
        }
        if meta.len() > cap {
            return Err(FileRefusal::TooLarge { cap });
        }
        Ok(())
    };
    check(&meta)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // O_NONBLOCK: a FIFO put there since the first look opens at once instead of waiting
        // for a writer (and is refused by the second look); a regular file reads as usual
        options.custom_flags(0o4000);
    }
    let file = options.open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    check(&meta)?;
    Ok((file, meta.len()))
}

/// The bytes of the regular file at `path`, at most `cap` ([`open_regular`]); the read stops
/// one byte past the cap, whatever size the file system reported.
pub fn read_bytes(path: &Path, cap: u64) -> Result<Vec<u8>, FileRefusal> {
    let (file, len) = open_regular(path, cap)?;
    let mut bytes = Vec::with_capacity(len.min(cap) as usize);
    file.take(cap.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > cap {
        return Err(FileRefusal::TooLarge { cap });
    }
    Ok(bytes)
}

/// The text of the regular file at `path`, at most `cap` bytes ([`read_bytes`]), UTF-8.
pub fn read_capped(path: &Path, cap: u64) -> Result<String, FileRefusal> {
    String::from_utf8(read_bytes(path, cap)?).map_err(|_| FileRefusal::NotText)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh directory for one test, under the system's temp dir.
    fn arena(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("fmu-beam-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("base")).unwrap();
        dir
    }

    #[cfg(unix)]
    fn link(target: &str, at: &Path) {
        std::os::unix::fs::symlink(target, at).unwrap();
    }

    #[test]
    fn devices_and_directories_are_refused_before_reading() {
        let e = read_capped(Path::new("/dev/zero"), 10).unwrap_err();
        assert_eq!(
            e.to_string(),
            "must be a regular file; this is a character device"
        );
        let e = read_capped(Path::new("/"), 10).unwrap_err();
        assert_eq!(e.to_string(), "must be a regular file; this is a directory");
    }

    #[test]
    fn names_that_leave_the_directory_are_refused() {
        let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        assert!(resolve_below(&here, "lib.rs").is_ok());
        assert!(resolve_below(&here, "scene/../lib.rs").is_ok());
        for name in [
            "/etc/passwd",
            "../Cargo.toml",
            ".",
            "",
            "scene/..",
            "scene/../../src/lib.rs",
        ] {
            assert!(resolve_below(&here, name).is_err(), "{name}");
        }
    }

    /// Issue 45: a refusal printed the canonical path a link led to, and told a missing file
    /// from one that exists outside; now every name that reaches nothing below the directory
    /// gets the same words, and none shows a path.
    #[cfg(unix)]
    #[test]
    fn a_refusal_tells_neither_where_a_link_leads_nor_which_files_exist() {
        let dir = arena("links");
        let base = dir.join("base");
        std::fs::write(base.join("inside.txt"), "length 1\n").unwrap();
        std::fs::write(dir.join("secret.txt"), "SECRET\n").unwrap();
        link("/etc/passwd", &base.join("to_passwd"));
        link("/etc/no-such-file", &base.join("dangling"));
        link("../secret.txt", &base.join("to_secret"));
        link("inside.txt", &base.join("to_inside"));
        assert!(read_below(&base, "to_inside", 100).is_ok());
        let refused = |name: &str| resolve_below(&base, name).unwrap_err().to_string();
        let linked = refused("to_passwd");
        for name in ["dangling", "to_secret", "missing.txt"] {
            assert_eq!(refused(name), linked, "{name}");
        }
        let outside = refused("/etc/passwd");
        assert_eq!(refused("/etc/no-such-file"), outside);
        assert_eq!(refused("../secret.txt"), outside);
        assert_eq!(refused("../no-such-file"), outside);
        for m in [&linked, &outside] {
            assert!(!m.contains('/') || !m.contains("etc"), "{m}");
            assert!(!m.contains(&*dir.to_string_lossy()), "{m}");
            assert!(!m.contains("secret"), "{m}");
        }
    }

    /// Issue 45: nothing of a refused file in the message, not its size nor where it stops
    /// being text.
    #[test]
    fn a_refusal_tells_no_size_and_no_offset() {
        let dir = arena("sizes");
        let big = dir.join("base/big.txt");
        std::fs::write(&big, "x".repeat(12345)).unwrap();
        let m = read_capped(&big, 100).unwrap_err().to_string();
        assert!(
            !m.contains("12345") && m.contains("at most 100 bytes"),
            "{m}"
        );
        let binary = dir.join("base/binary.txt");
        std::fs::write(&binary, b"abcdefg\xff\xfe").unwrap();
        let m = read_capped(&binary, 100).unwrap_err().to_string();
        assert!(!m.contains('7') && m.contains("UTF-8"), "{m}");
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_at_once() {
        let dir = arena("fifo");
        let fifo = dir.join("base/pipe.txt");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let e = read_below(&dir.join("base"), "pipe.txt", 100).unwrap_err();
        assert_eq!(e.to_string(), "must be a regular file; this is a FIFO");
    }
}
