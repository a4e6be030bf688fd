//! The FMU's `resources/` directory, as fmi2Instantiate receives it (`fmuResourceLocation`, a
//! `file:` URI), and the two files the packager writes there: `scene.toml` and `guid.txt`.

use crate::scene::Scene;
use std::path::{Path, PathBuf};

/// The directory named by `fmuResourceLocation`.
///
/// Accepted: `file:///abs/path`, `file:/abs/path`, `file://localhost/abs/path`, with or without
/// a trailing slash, percent-encoded (`%20`); also a bare absolute path, taken literally.
pub fn directory(location: &str) -> Result<PathBuf, String> {
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
                if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
                    return Err(refuse(&format!(
                        "names the host '{host}': only local files can be read"
                    )));
                }
                if path.is_empty() {
                    return Err(refuse("has no path"));
                }
                percent_decode(path).map_err(|e| refuse(&e))?
            }
            None if rest.starts_with('/') => percent_decode(rest).map_err(|e| refuse(&e))?,
            None => return Err(refuse("is not an absolute path")),
        },
        None if location.starts_with('/') => location.to_string(),
        None => return Err(refuse("is not a file URI")),
    };
    let trimmed = path.trim_end_matches('/');
    Ok(PathBuf::from(if trimmed.is_empty() {
        "/"
    } else {
        trimmed
    }))
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

/// The GUID the packager wrote into `guid.txt` (trimmed).
pub fn guid(dir: &Path) -> Result<String, String> {
    let path = dir.join("guid.txt");
    let text = std::fs::read_to_string(&path)
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
}
