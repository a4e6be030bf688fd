//! The FMU's `resources/` directory, as fmi2Instantiate receives it (`fmuResourceLocation`, a
//! `file:` URI), and the two files the packager writes there: `scene.toml` and `guid.txt`.

use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// The directory named by `fmuResourceLocation`, read as this platform reads paths
/// ([`directory_text`] with `windows = cfg!(windows)`).
pub fn directory(location: &str) -> Result<PathBuf, String> {
    directory_text(location, cfg!(windows)).map(PathBuf::from)
}

/// The path text of the directory named by `fmuResourceLocation`.
///
/// Accepted everywhere: `file:///abs/path`, `file:/abs/path`, `file://localhost/abs/path`, with
/// or without a trailing slash, percent-encoded (`%20`); also a bare absolute path, taken
/// literally. With `windows` (what masters on Windows send): a drive letter after the URI's
/// slash (`file:///C:/dir` → `C:/dir`, also `file://C:/dir`), a host as a network share
/// (`file://server/share/dir` → `//server/share/dir`), and bare `C:\dir` or `\\server\share`
/// paths.
pub fn directory_text(location: &str, windows: bool) -> Result<String, String> {
    let refuse = |why: &str| {
        format!(
            "fmuResourceLocation '{location}' {why}; expected a file URI such as \
             file:///path/to/resources"
        )
    };
    let path = match strip_prefix_ignore_case(location, "file:") {
        Some(rest) => match rest.strip_prefix("//") {
            Some(authority_and_path) => {
                let slash = authority_and_path
                    .find('/')
                    .unwrap_or(authority_and_path.len());
                let (host, path) = authority_and_path.split_at(slash);
                let path = if host.is_empty() || host.eq_ignore_ascii_case("localhost") {
                    path.to_string()
                } else if windows && is_drive(host) {
                    format!("/{host}{path}")
                } else if windows {
                    format!("//{host}{path}")
                } else {
                    return Err(refuse(&format!(
                        "names the host '{host}': only local files can be read"
                    )));
                };
                if path.is_empty() {
                    return Err(refuse("has no path"));
                }
                percent_decode(&path).map_err(|e| refuse(&e))?
            }
            None if rest.starts_with('/') => percent_decode(rest).map_err(|e| refuse(&e))?,
            None => return Err(refuse("is not an absolute path")),
        },
        None if location.starts_with('/') => location.to_string(),
        None if windows && (location.starts_with('\\') || starts_with_drive(location)) => {
            location.to_string()
        }
        None => return Err(refuse("is not a file URI")),
    };
    // `/C:/dir` is a URI's path of `C:/dir`; only Windows has drive letters
    let path = match path.strip_prefix('/') {
        Some(rest) if windows && starts_with_drive(rest) => rest,
        _ => path.as_str(),
    };
    let trimmed = if windows {
        path.trim_end_matches(['/', '\\'])
    } else {
        path.trim_end_matches('/')
    };
    Ok(if trimmed.is_empty() {
        "/".to_string()
    } else if windows && is_drive(trimmed) {
        format!("{trimmed}/")
    } else {
        trimmed.to_string()
    })
}

/// `C:` (a drive letter and a colon, nothing more).
fn is_drive(s: &str) -> bool {
    let b = s.as_bytes();
    b.len() == 2 && b[0].is_ascii_alphabetic() && b[1] == b':'
}

/// `C:`, then the end or a slash or backslash.
fn starts_with_drive(s: &str) -> bool {
    s.get(..2).is_some_and(is_drive) && matches!(s.as_bytes().get(2), None | Some(b'/' | b'\\'))
}

fn strip_prefix_ignore_case<'a>(s: &'a str, prefix: &str) -> Option<&'a str> {
    let head = s.get(..prefix.len())?;
    head.eq_ignore_ascii_case(prefix)
        .then(|| &s[prefix.len()..])
}

/// `%XX` escapes to bytes; the result must be UTF-8.
fn percent_decode(s: &str) -> Result<String, String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok());
            match hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                Some(byte) => out.push(byte),
                None => return Err(format!("has a bad percent escape at byte {i}")),
            }
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "decodes to a path that is not UTF-8".to_string())
}

/// The most `guid.txt` may hold (bytes).
const GUID_FILE_CAP: u64 = 1024;

/// The GUID the packager wrote into `guid.txt` (trimmed).
pub fn guid(dir: &Path) -> Result<String, String> {
    let path = dir.join("guid.txt");
    // a regular file of a few bytes (a GUID is 36 characters); never a FIFO or a device
    let text = crate::scene::files::read_capped(&path, GUID_FILE_CAP)
        .map_err(|e| format!("{}: cannot read the GUID of this FMU: {e}", path.display()))?;
    let guid = text.trim();
    if guid.is_empty() {
        return Err(format!("{}: the GUID of this FMU is empty", path.display()));
    }
    Ok(guid.to_string())
}

/// The scene in `scene.toml`, read and validated; errors name the file, field and rule.
pub fn scene(dir: &Path) -> Result<Scene, String> {
    Scene::load(&dir.join("scene.toml")).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uri_forms() {
        let p = |s: &str| directory(s).map(|p| p.display().to_string());
        assert_eq!(p("file:///a/b%20c/").as_deref(), Ok("/a/b c"));
        assert_eq!(p("file:/a/b").as_deref(), Ok("/a/b"));
        assert_eq!(p("FILE://localhost/a/b/").as_deref(), Ok("/a/b"));
        assert_eq!(p("/a/b%20c").as_deref(), Ok("/a/b%20c"));
        assert!(p("file://server/a").unwrap_err().contains("host 'server'"));
        assert!(p("file:a/b").is_err());
        assert!(p("http://x/a").is_err());
        assert!(p("file:///a/%zz").unwrap_err().contains("percent escape"));
        assert!(p("file:///a/%2").is_err());
    }

    /// What masters on Windows send (fmpy: `Path.as_uri()`, `file:///C:/...`), read as Windows
    /// reads it; on Linux the same texts are refused or stay Unix paths.
    #[test]
    fn windows_uri_forms() {
        let w = |s: &str| directory_text(s, true);
        let ok = |s: &str| Ok::<String, String>(s.to_string());
        assert_eq!(
            w("file:///C:/Users/a%20b/fmu/resources/"),
            ok("C:/Users/a b/fmu/resources")
        );
        assert_eq!(w("file:/c:/fmu/resources"), ok("c:/fmu/resources"));
        assert_eq!(w("file://localhost/Z:/tmp/r"), ok("Z:/tmp/r"));
        assert_eq!(w("file://C:/fmu/resources"), ok("C:/fmu/resources"));
        assert_eq!(w("file:///C:/"), ok("C:/"));
        assert_eq!(w("file:///C:"), ok("C:/"));
        assert_eq!(
            w("file://server/share/fmu/resources"),
            ok("//server/share/fmu/resources")
        );
        assert_eq!(w(r"C:\fmu\resources\"), ok(r"C:\fmu\resources"));
        assert_eq!(w(r"\\server\share\r"), ok(r"\\server\share\r"));
        assert_eq!(w("file:///a/b"), ok("/a/b"));
        assert!(w("fmu/resources").is_err());
        assert!(w("C:fmu").is_err());
        // the same texts on Linux
        assert!(directory_text("file://server/share/r", false).is_err());
        assert_eq!(directory_text("file:///C:/r", false), ok("/C:/r"));
        assert!(directory_text(r"C:\r", false).is_err());
    }

    /// `guid.txt` is read only as a small regular file: a FIFO or a huge file in an FMU's
    /// resources is refused at once, with no byte of it in the message (issue 35).
    #[cfg(unix)]
    #[test]
    fn the_guid_file_is_small_and_regular() {
        let dir = std::env::temp_dir().join(format!("fmu-beam-guid-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("guid.txt");
        std::fs::write(&path, "  {1234}\n").unwrap();
        assert_eq!(guid(&dir), Ok("{1234}".to_string()));
        std::fs::write(&path, "SECRET".repeat(1000)).unwrap();
        let e = guid(&dir).unwrap_err();
        assert!(
            e.contains("at most 1024 bytes") && !e.contains("SECRET"),
            "{e}"
        );
        std::fs::remove_file(&path).unwrap();
        let made = std::process::Command::new("mkfifo").arg(&path).status();
        if made.is_ok_and(|s| s.success()) {
            let e = guid(&dir).unwrap_err();
            assert!(e.contains("regular file"), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
