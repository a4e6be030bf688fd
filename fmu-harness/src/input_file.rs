//! A file named to the harness, read with care (issue 35, item 2; issue 45): through the
//! engine's one reader, [`fmu_beam::scene::files::read_bytes`]. It must be a regular file (its
//! type is checked from the metadata before opening and again on the open file, opened
//! non-blocking, so that a FIFO or a device is refused at once instead of blocking or reading
//! forever), and no more than a cap is read, whatever size the file system reports. A refusal
//! names the path as the user gave it and tells nothing of the file's bytes or size.

use fmu_beam::scene::files::{self, FileRefusal};
use std::path::{Path, PathBuf};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum InputFileError {
    #[error("{}: {action}: {message}", .path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        message: String,
    },
    #[error("{}: a {kind}; {what} must be a regular file", .path.display())]
    NotRegular {
        path: PathBuf,
        what: &'static str,
        kind: &'static str,
    },
    #[error("{}: larger than {limit} bytes, the most {what} may have", .path.display())]
    TooLarge {
        path: PathBuf,
        what: &'static str,
        limit: u64,
    },
    #[error("{}: {what} must be UTF-8 text, and is not", .path.display())]
    NotText { path: PathBuf, what: &'static str },
}

impl InputFileError {
    /// A refusal of the engine's reader ([`files`]), for the file `path`, `what` in words.
    pub fn of(e: FileRefusal, path: &Path, what: &'static str) -> InputFileError {
        let path = path.to_path_buf();
        match e {
            FileRefusal::NotRegular { kind } => InputFileError::NotRegular { path, what, kind },
            FileRefusal::TooLarge { cap } => InputFileError::TooLarge {
                path,
                what,
                limit: cap,
            },
            FileRefusal::NotText => InputFileError::NotText { path, what },
            other => InputFileError::Io {
                path,
                action: "reading",
                message: match other {
                    FileRefusal::Io { message } => message,
                    o => o.to_string(),
                },
            },
        }
    }
}

/// The bytes of `path` (`what` names it in messages: "an engine library"), or why not: not a
/// regular file, more than `limit` bytes, unreadable.
pub fn read(path: &Path, what: &'static str, limit: u64) -> Result<Vec<u8>, InputFileError> {
    files::read_bytes(path, limit).map_err(|e| InputFileError::of(e, path, what))
}

/// The regular file at `path` open for reading (`what` names it in messages: "the FMU"),
/// checked without blocking ([`files::open_regular`]): a FIFO or a device is refused, not
/// opened. No cap: the caller bounds what it reads.
pub fn open(path: &Path, what: &'static str) -> Result<std::fs::File, InputFileError> {
    files::open_regular(path, u64::MAX)
        .map(|(f, _)| f)
        .map_err(|e| InputFileError::of(e, path, what))
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
        assert!(e
            .to_string()
            .contains("a directory; a test file must be a regular file"));
    }
}
