//! `animate -o` writes the format its file's extension names (issue 31): a .gif is a GIF, a
//! .html the page; any other extension is refused before the run is made, with nothing written
//! (before, `-o anim.gif` wrote an HTML page under the GIF's name, silently).

use crate::common;
use common::*;
use std::ffi::OsStr;

fn animate(dir: &std::path::Path, out: &str) -> std::process::Output {
    let scene = c1_path();
    harness(&[
        "animate".as_ref(),
        scene.as_os_str(),
        "--stop".as_ref(),
        "0.004".as_ref(),
        "-o".as_ref(),
        dir.join(out).as_os_str(),
    ])
}

#[test]
fn the_extension_of_the_output_picks_the_format() {
    let dir = scratch("animate_format");
    let gif = animate(&dir, "anim.gif");
    assert!(
        gif.status.success(),
        "{}",
        String::from_utf8_lossy(&gif.stderr)
    );
    let bytes = std::fs::read(dir.join("anim.gif")).unwrap();
    assert_eq!(&bytes[..6], b"GIF89a", "a GIF, not a page");
    let page = animate(&dir, "anim.HTML");
    assert!(
        page.status.success(),
        "{}",
        String::from_utf8_lossy(&page.stderr)
    );
    let text = std::fs::read_to_string(dir.join("anim.HTML")).unwrap();
    assert!(
        text.trim_start()
            .to_lowercase()
            .starts_with("<!doctype html"),
        "{}",
        &text[..80]
    );
}

#[test]
fn an_unknown_extension_is_refused_and_nothing_is_written() {
    let dir = scratch("animate_unknown_format");
    for out in ["anim.png", "anim"] {
        let r = animate(&dir, out);
        let e = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success());
        assert!(
            e.contains("the format comes from the extension: .html (or .htm) for the page, .gif"),
            "{e}"
        );
        assert!(!dir.join(out).exists());
    }
    let both = harness(&[
        "animate".as_ref(),
        c1_path().as_os_str(),
        "-o".as_ref(),
        dir.join("a.gif").as_os_str(),
        "--gif".as_ref(),
        OsStr::new("b.gif"),
    ]);
    assert!(!both.status.success());
    assert!(String::from_utf8_lossy(&both.stderr).contains("give one"));
}
