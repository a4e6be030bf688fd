//! The self-contained page: the run's data and the player (a canvas, a time slider,
//! play/pause, speed, the magnification, in 3D a view turned with the mouse), everything
//! inline, so it opens from a file with no network.

use super::Motion;

/// The player, with `__DATA__` where the run goes.
const TEMPLATE: &str = include_str!("page.html");
/// Most recorded times the page carries (more are thinned evenly).
pub const MAX_PAGE_TIMES: usize = 2500;

/// Indices of the recorded times the page carries: all, or evenly thinned to
/// [`MAX_PAGE_TIMES`] with the last one kept.
pub fn page_times(m: &Motion) -> Vec<usize> {
    let n = m.times.len();
    if n <= MAX_PAGE_TIMES {
        return (0..n).collect();
    }
    let mut k: Vec<usize> = (0..MAX_PAGE_TIMES)
        .map(|i| i * (n - 1) / (MAX_PAGE_TIMES - 1))
        .collect();
    k.dedup();
    k
}

/// Numbers as a JSON array, rounded to `decimals`.
fn nums(v: impl Iterator<Item = f64>, decimals: usize) -> String {
    let parts: Vec<String> = v
        .map(|x| {
            let s = format!("{x:.decimals$}");
            let s = if s.contains('.') {
                s.trim_end_matches('0').trim_end_matches('.').to_string()
            } else {
                s
            };
            if s == "-0" {
                "0".to_string()
            } else {
                s
            }
        })
        .collect();
    format!("[{}]", parts.join(","))
}

fn text(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".into())
}

/// The page of a run with default magnification `magnification` and playback speed `speed`.
pub fn page(m: &Motion, magnification: f64, speed: f64) -> String {
    let keep = page_times(m);
    let pick = |v: &[f64], width: usize| -> Vec<f64> {
        keep.iter()
            .flat_map(|&r| v[r * width..(r + 1) * width].iter().copied())
            .collect()
    };
    // positions to 1e-7 of the largest beam length: far below a pixel at any magnification
    // the page offers
    let size = m
        .beams
        .iter()
        .map(|b| b.length)
        .fold(0.0, f64::max)
        .max(1e-9);
    let decimals = ((-(size * 1e-7).log10()).ceil().max(0.0) as usize).min(15);
    let beams: Vec<String> = m
        .beams
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let [r, g, bl] = super::gif::beam_rgb(k);
            format!(
                "{{\"name\":{},\"n\":{},\"length\":{},\"color\":\"rgb({r},{g},{bl})\",\"points\":{},\"axis\":{}}}",
                text(&b.name),
                b.n,
                b.length,
                nums(pick(&b.points, 3 * b.n).into_iter(), decimals),
                nums(pick(&b.axis, 3).into_iter(), 6)
            )
        })
        .collect();
    let bodies: Vec<String> = m
        .bodies
        .iter()
        .map(|b| {
            format!(
                "{{\"name\":{},\"position\":{},\"rotation\":{}}}",
                text(&b.name),
                nums(pick(&b.position, 3).into_iter(), decimals),
                nums(pick(&b.rotation, 9).into_iter(), 6)
            )
        })
        .collect();
    let joints: Vec<String> = m
        .joints
        .iter()
        .map(|j| {
            format!(
                "{{\"name\":{},\"kind\":{},\"grounded\":{},\"rail\":{},\"position\":{}}}",
                text(&j.name),
                text(j.kind),
                j.grounded,
                j.rail.map_or("null".into(), |a| nums(a.into_iter(), 6)),
                nums(pick(&j.position, 3).into_iter(), decimals)
            )
        })
        .collect();
    let data = format!(
        "{{\"title\":{},\"dims\":{},\"magnification\":{},\"largest_deflection\":{},\"speed\":{},\"times\":{},\"beams\":[{}],\"bodies\":[{}],\"joints\":[{}]}}",
        text(&m.title),
        m.dims,
        magnification,
        m.largest_deflection_ratio(),
        speed,
        nums(keep.iter().map(|&r| m.times[r]), 9),
        beams.join(","),
        bodies.join(","),
        joints.join(",")
    );
    // inside a <script> element, "</" would end it
    TEMPLATE
        .replace("__TITLE__", &html_escape(&m.title))
        .replace("__DATA__", &data.replace("</", "<\\/"))
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
