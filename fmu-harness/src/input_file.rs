//! A file named to the harness, read with care (issue 35, item 2): it must be a regular file
//! (its type is checked from the metadata before opening and again on the open file, opened
//! non-blocking, so that a FIFO or a device is refused at once instead of blocking or reading
//! forever), and no more than a cap is read, whatever size the file system reports.

use std::io::Read;
use std::path::{Path, PathBuf};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum InputFileError {
    #[error("{}: {action}: {source}", .path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        source: std::io::Error,
    },
    #[error("{}: {kind}; {what} must be a regular file", .path.display())]
    NotRegular {
        path: PathBuf,
        what: &'static str,
        kind: &'static str,
    },
    #[error("{}: {bytes} bytes or more; {what} may have at most {limit}", .path.display())]
    TooLarge {
        path: PathBuf,
        what: &'static str,
        bytes: u64,
        limit: u64,
    },
    #[error("{}: {what} must be UTF-8 text, and is not", .path.display())]
    NotText { path: PathBuf, what: &'static str },
}

/// What a file that is not a regular file is, for messages.
fn file_kind(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }
}

/// The bytes of `path` (`what` names it in messages: "an engine library"), or why not: not a
/// regular file, more than `limit` bytes, unreadable.
pub fn read(path: &Path, what: &'static str, limit: u64) -> Result<Vec<u8>, InputFileError> {
    let not_regular = |t: std::fs::FileType| InputFileError::NotRegular {
        path: path.to_path_buf(),
        what,
        kind: file_kind(t),
    };
    let too_large = |bytes: u64| InputFileError::TooLarge {
        path: path.to_path_buf(),
        what,
        bytes,
        limit,
    };
    let io = |source| InputFileError::Io {
        path: path.to_path_buf(),
        action: "reading",
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(meta.file_type()));
    }
    if meta.len() > limit {
        return Err(too_large(meta.len()));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(target_os = "linux")]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // O_NONBLOCK: a FIFO put there since the check opens at once instead of waiting.
        options.custom_flags(0o4000);
    }
    let file = options.open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(meta.file_type()));
    }
    let mut bytes = Vec::with_capacity(meta.len().min(limit) as usize);
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// [`read`], as UTF-8 text (refused, without quoting it, if it is not).
pub fn read_text(path: &Path, what: &'static str, limit: u64) -> Result<String, InputFileError> {
    String::from_utf8(read(path, what, limit)?).map_err(|_| InputFileError::NotText {
        path: path.to_path_buf(),
        what,
    })
}

/// Line and column (1-based, in characters) of byte `pos` of `text`, for messages that say
/// where a file is wrong without quoting it.
pub fn line_column(text: &str, pos: usize) -> (usize, usize) {
    let mut pos = pos.min(text.len());
    while !text.is_char_boundary(pos) {
        pos -= 1;
    }
    let before = &text[..pos];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_columns_count_characters() {
        assert_eq!(line_column("ab\ncé\nx", 0), (1, 1));
        assert_eq!(line_column("ab\ncé\nx", 3), (2, 1));
        assert_eq!(line_column("ab\ncé\nx", 5), (2, 2)); // inside `é`: its start
        assert_eq!(line_column("ab\ncé\nx", 7), (3, 1));
        assert_eq!(line_column("ab", 99), (1, 3));
    }

    #[test]
    fn devices_and_folders_are_refused_by_type() {
        let e = read(Path::new("/dev/null"), "a test file", 10).unwrap_err();
        assert!(e
            .to_string()
            .contains("a character device; a test file must be a regular file"));
        let e = read(Path::new("/"), "a test file", 10).unwrap_err();
        assert!(e.to_string().contains("a folder"));
    }
}
