//! Reading the files a scene names, as a receiver of scene files from others must (issue 35):
//! a named file is resolved below the scene file's directory after following links, read only
//! if it is a regular file (checked before it is opened: a FIFO or a device would block or
//! never end), and read no further than a cap, enforced while reading. No refusal quotes a
//! byte of the file.

use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest scene text read or parsed (bytes): a hand-written scene, or a packaged one with its
/// matrix files' texts inside. Shipped scenes are under 4 KiB.
pub const MAX_SCENE_BYTES: u64 = 4 << 20;
/// Largest matrix file read (bytes): the two 12 × 12 matrices at 17 digits take about 8 KiB,
/// so this leaves room for comments.
pub const MAX_MATRIX_FILE_BYTES: u64 = 64 << 10;

/// Why a named file was not read. The text of each variant is the rule a refusal names; none
/// carries a byte of the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FileRefusal {
    /// The path leaves the scene file's directory (absolute, `..`, or a link that points out).
    #[error("must name a file below the scene file's directory {dir} (links followed); it resolves to {resolved}")]
    Outside {
        /// The scene's directory, canonical.
        dir: String,
        /// Where the name leads, canonical.
        resolved: String,
    },
    /// Not a regular file (a directory, a FIFO, a device, a socket).
    #[error("must be a regular file; this is a {kind}")]
    NotRegular {
        /// What it is instead.
        kind: &'static str,
    },
    /// Larger than the cap (by its size, or found so while reading).
    #[error("must be at most {cap} bytes; it has {size}")]
    TooLarge {
        /// Its size as far as it was read or reported (bytes).
        size: String,
        /// The cap (bytes).
        cap: u64,
    },
    /// Not UTF-8 text.
    #[error("must be UTF-8 text; byte {at} is not")]
    NotText {
        /// Offset of the first byte that is not valid UTF-8.
        at: usize,
    },
    /// The system refused (no such file, permission, …).
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

/// `name` (as a scene wrote it) resolved below `dir` (the scene file's directory), both with
/// their links followed; refused if it leads elsewhere.
pub fn resolve_below(dir: &Path, name: &str) -> Result<PathBuf, FileRefusal> {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let base = dir.canonicalize().map_err(io)?;
    let resolved = base.join(name).canonicalize().map_err(io)?;
    if resolved.starts_with(&base) && resolved != base {
        Ok(resolved)
    } else {
        Err(FileRefusal::Outside {
            dir: base.display().to_string(),
            resolved: resolved.display().to_string(),
        })
    }
}

/// What a file that is not regular is.
fn kind_of(t: std::fs::FileType) -> &'static str {
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
        }
    }
    "special file"
}

/// The text of the regular file at `path`, at most `cap` bytes: its type and size are checked
/// before it is opened, and the read stops one byte past the cap.
pub fn read_capped(path: &Path, cap: u64) -> Result<String, FileRefusal> {
    let meta = std::fs::metadata(path).map_err(io)?;
    let check = |meta: &std::fs::Metadata| {
        if !meta.is_file() {
            return Err(FileRefusal::NotRegular {
                kind: kind_of(meta.file_type()),
            });
        }
        if meta.len() > cap {
            return Err(FileRefusal::TooLarge {
                size: meta.len().to_string(),
                cap,
            });
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
        // for a writer (and is refused by the second look)
        options.custom_flags(0o4000);
    }
    let file = options.open(path).map_err(io)?;
    // the file may have been swapped between the two looks: look again at what was opened
    check(&file.metadata().map_err(io)?)?;
    let mut bytes = Vec::new();
    file.take(cap.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > cap {
        return Err(FileRefusal::TooLarge {
            size: format!("more than {cap}"),
            cap,
        });
    }
    String::from_utf8(bytes).map_err(|e| FileRefusal::NotText {
        at: e.utf8_error().valid_up_to(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_and_directories_are_refused_before_reading() {
        let e = read_capped(Path::new("/dev/zero"), 10).unwrap_err();
        assert_eq!(
            e,
            FileRefusal::NotRegular {
                kind: "character device"
            }
        );
        let e = read_capped(Path::new("/"), 10).unwrap_err();
        assert!(matches!(e, FileRefusal::NotRegular { kind: "directory" }));
    }

    #[test]
    fn names_that_leave_the_directory_are_refused() {
        let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        assert!(resolve_below(&here, "lib.rs").is_ok());
        assert!(resolve_below(&here, "scene/../lib.rs").is_ok());
        for name in ["/etc/passwd", "../Cargo.toml", ".", ""] {
            let e = resolve_below(&here, name).unwrap_err();
            assert!(matches!(e, FileRefusal::Outside { .. }), "{name}: {e}");
        }
    }
}
