//! Every file the harness writes (issue 45, item 3), in one place: an output is a new name or
//! a regular file, never a FIFO, a device, a directory or a symbolic link ([`check`]). A link
//! is refused whatever it points to: written through, it would change a file elsewhere (one a
//! hostile workspace chose); replaced, the link the user made would be lost. The bytes go to a
//! temporary file beside the target (created new, so no link there is followed; registered,
//! so that it goes on an error or a signal), which is renamed over the target only when it is
//! complete and the target, looked at again, is still a regular file or missing: the target
//! is whole or as it was. The check runs again before the rename, and the callers run it before
//! any work too, so that a refused output costs nothing. A file swapped in between the last
//! look and the rename is not caught (that would take `renameat2`, which needs unsafe code).

use crate::error::HarnessError;
use crate::scratch::Scratch;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Refuses `path` as an output unless it names a file (not a directory path) that is missing
/// or a regular file, not a link. The message gives the path as the user wrote it and what it
/// is, never where a link leads.
pub fn check(path: &Path) -> Result<(), HarnessError> {
    let text = path.as_os_str().to_string_lossy();
    if path.file_name().is_none() || text.ends_with('/') {
        return Err(HarnessError::BadOutput {
            path: path.to_path_buf(),
        });
    }
    match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(HarnessError::io(path, "looking at the output", e)),
        Ok(m) if m.file_type().is_file() => Ok(()),
        Ok(m) => Err(HarnessError::NotRegularOutput {
            path: path.to_path_buf(),
            kind: fmu_beam::scene::files::kind_of(m.file_type()),
        }),
    }
}

/// [`check`] of each path given.
pub fn check_all<'a>(paths: impl IntoIterator<Item = &'a Path>) -> Result<(), HarnessError> {
    paths.into_iter().try_for_each(check)
}

/// A new temporary name beside `path`: `.<name>.tmp-<pid>-<n>` (unique within the process, so
/// that threads writing the same target do not meet).
fn temporary_beside(path: &Path) -> Result<PathBuf, HarnessError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| HarnessError::BadOutput {
            path: path.to_path_buf(),
        })?
        .to_string_lossy()
        .into_owned();
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    Ok(path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id())))
}

/// Runs `write` on a new temporary file beside `path` (its folder created if missing), then,
/// when it succeeded, syncs the file and renames it over `path`; on any failure the temporary
/// file goes and `path` is as it was. `what` names the file in messages ("the FMU").
pub fn write_through_temporary<T>(
    path: &Path,
    what: &'static str,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> Result<T, HarnessError>,
) -> Result<T, HarnessError> {
    check(path)?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| HarnessError::io(dir, "creating the output's folder", e))?;
    }
    let tmp = temporary_beside(path)?;
    let (scratch, file) = Scratch::file(&tmp).map_err(|e| HarnessError::io(&tmp, what, e))?;
    let mut out = std::io::BufWriter::new(file);
    let value = write(&mut out)?;
    out.into_inner()
        .map_err(|e| e.into_error())
        .and_then(|f| f.sync_all())
        .map_err(|e| HarnessError::io(path, what, e))?;
    // what is there now may differ from what was there when the work began
    check(path)?;
    scratch
        .persist(path)
        .map_err(|e| HarnessError::io(path, what, e))?;
    Ok(value)
}

/// Writes `bytes` to `path` whole or not at all ([`write_through_temporary`]).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), HarnessError> {
    write_through_temporary(path, "writing the file", |out| {
        out.write_all(bytes)
            .map_err(|e| HarnessError::io(path, "writing the file", e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_missing_name_or_a_regular_file_is_an_output() {
        let dir = std::env::temp_dir().join(format!("fmu-harness-output-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        assert!(check(&dir.join("new.csv")).is_ok());
        std::fs::write(dir.join("old.csv"), "old").unwrap();
        assert!(check(&dir.join("old.csv")).is_ok());
        let e = check(&dir).unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
        let e = check(Path::new("/dev/null")).unwrap_err().to_string();
        assert!(e.contains("a character device"), "{e}");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink("old.csv", dir.join("link.csv")).unwrap();
            let e = check(&dir.join("link.csv")).unwrap_err().to_string();
            assert!(
                e.contains("a symbolic link") && !e.contains("old.csv"),
                "{e}"
            );
        }
        assert!(check(Path::new("some/dir/")).is_err());
        write_atomically(&dir.join("old.csv"), b"new").unwrap();
        assert_eq!(std::fs::read(dir.join("old.csv")).unwrap(), b"new");
        let left = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(left, 2, "a temporary file left");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
