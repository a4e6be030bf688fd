//! The Campbell diagram: the natural frequencies at each hub speed of a range, as CSV (speed,
//! then one column per mode) and as a PNG (one line per mode, with the 1× and 2× per-revolution
//! excitation lines f = kΩ/2π), drawn with `embedded-graphics` as `animate` draws its GIF.

use crate::chart::Canvas;
use crate::error::HarnessError;
use embedded_graphics::mono_font::{ascii::FONT_7X13, MonoTextStyle};
use embedded_graphics::pixelcolor::Rgb888;
use embedded_graphics::prelude::*;
use embedded_graphics::primitives::{Circle, Line, PrimitiveStyle, Rectangle};
use embedded_graphics::text::{Alignment, Text};
use fmu_beam::{ModeOptions, Modes, Scene};
use std::f64::consts::TAU;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Hub speeds `START:STOP:COUNT` (rad/s), COUNT ≥ 2 points evenly spaced, ends included.
pub fn parse_speeds(spec: &str) -> Result<Vec<f64>, HarnessError> {
    let bad = |why: &str| HarnessError::Input {
        origin: "--campbell".into(),
        message: format!("'{spec}': {why} (START:STOP:COUNT in rad/s, e.g. 0:10:21)"),
    };
    let parts: Vec<&str> = spec.split(':').collect();
    let [a, b, n] = parts.as_slice() else {
        return Err(bad("three fields expected"));
    };
    let (a, b): (f64, f64) = match (a.trim().parse(), b.trim().parse()) {
        (Ok(a), Ok(b)) => (a, b),
        _ => return Err(bad("START and STOP must be numbers")),
    };
    let n: usize = n.trim().parse().map_err(|_| bad("COUNT must be a count"))?;
    if !(a.is_finite() && b.is_finite()) || a < 0.0 || b <= a {
        return Err(bad("0 <= START < STOP expected"));
    }
    if !(2..=1000).contains(&n) {
        return Err(bad("COUNT from 2 to 1000"));
    }
    Ok((0..n)
        .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
        .collect())
}

/// The modes of `scene` at each of `speeds` (the other options as given), computed on `jobs`
/// threads (at most one per speed; 0: all cores), each taking the next speed from a shared
/// counter. Each speed's modes are computed alone, so the result is a serial run's, in speed
/// order; an error is the one of the first speed that failed (later speeds are not started).
pub fn modes_at_speeds(
    scene: &Scene,
    origin: &str,
    options: &ModeOptions,
    speeds: &[f64],
    jobs: usize,
) -> Result<Vec<Modes>, HarnessError> {
    let jobs = if jobs == 0 { default_jobs() } else { jobs }.clamp(1, speeds.len().max(1));
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let run = || {
        let mut done = Vec::new();
        loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            if k >= speeds.len() || failed.load(Ordering::Relaxed) {
                return done;
            }
            let o = ModeOptions {
                speed: speeds[k],
                ..options.clone()
            };
            let m = super::modes_of(scene, origin, &o);
            failed.fetch_or(m.is_err(), Ordering::Relaxed);
            done.push((k, m));
        }
    };
    let mut results: Vec<(usize, Result<Modes, HarnessError>)> = if jobs == 1 {
        run()
    } else {
        std::thread::scope(|s| {
            let workers: Vec<_> = (0..jobs).map(|_| s.spawn(run)).collect();
            workers
                .into_iter()
                .flat_map(|w| w.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .collect()
        })
    };
    results.sort_by_key(|(k, _)| *k);
    let mut out = Vec::with_capacity(speeds.len());
    for (_, m) in results {
        out.push(m?);
    }
    Ok(out)
}

/// The threads a study runs on by default: every core the process may use.
pub fn default_jobs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// One row per speed: the speed (rad/s) and the first frequencies (Hz).
#[derive(Debug, Clone, PartialEq)]
pub struct Diagram {
    /// Hub speeds (rad/s).
    pub speeds: Vec<f64>,
    /// At each speed, the frequencies (Hz, ascending), at most the count asked for.
    pub frequencies: Vec<Vec<f64>>,
}

impl Diagram {
    /// The number of mode columns.
    pub fn modes(&self) -> usize {
        self.frequencies.iter().map(Vec::len).max().unwrap_or(0)
    }

    /// CSV: `speed_rad_s,mode1_Hz,…`, one row per speed (an empty cell where a mode is missing).
    pub fn csv(&self) -> String {
        let k = self.modes();
        let mut s = String::from("speed_rad_s");
        for i in 1..=k {
            s += &format!(",mode{i}_Hz");
        }
        s.push('\n');
        for (w, f) in self.speeds.iter().zip(&self.frequencies) {
            s += &format!("{w}");
            for i in 0..k {
                s.push(',');
                if let Some(x) = f.get(i) {
                    s += &format!("{x}");
                }
            }
            s.push('\n');
        }
        s
    }

    /// The PNG bytes of the diagram (`width` × `height` pixels).
    pub fn png(&self, title: &str, width: u32, height: u32) -> Vec<u8> {
        let mut c = Canvas::new(width, height);
        draw(&mut c, self, title);
        c.png()
    }
}

/// The modes' colours (matplotlib's tab10, as the animation's beams).
const MODE_COLOURS: [Rgb888; 8] = [
    Rgb888::new(31, 119, 180),
    Rgb888::new(255, 127, 14),
    Rgb888::new(44, 160, 44),
    Rgb888::new(214, 39, 40),
    Rgb888::new(148, 103, 189),
    Rgb888::new(140, 86, 75),
    Rgb888::new(227, 119, 194),
    Rgb888::new(23, 190, 207),
];

/// A round step for about 5 ticks up to `top`.
fn tick(top: f64) -> f64 {
    let raw = top / 5.0;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

fn label(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn draw(c: &mut Canvas, d: &Diagram, title: &str) {
    let (w, h) = (c.size().width as f64, c.size().height as f64);
    let (left, right, top, bottom) = (64.0, w - 16.0, 30.0, h - 44.0);
    let xmax = d.speeds.last().copied().unwrap_or(1.0).max(1e-12);
    let fmax = d
        .frequencies
        .iter()
        .flatten()
        .fold(0.0f64, |a, &b| a.max(b))
        .max(1e-12)
        * 1.05;
    let at = |x: f64, y: f64| {
        Point::new(
            (left + (right - left) * x / xmax).round() as i32,
            (bottom - (bottom - top) * y / fmax).round() as i32,
        )
    };
    let ink = Rgb888::new(40, 40, 40);
    let pale = Rgb888::new(215, 215, 215);
    let text = MonoTextStyle::new(&FONT_7X13, ink);
    // grid and ticks
    let (sx, sy) = (tick(xmax), tick(fmax));
    let mut x = 0.0;
    while x <= xmax * (1.0 + 1e-9) {
        let p = at(x, 0.0);
        let _ = Line::new(p, at(x, fmax))
            .into_styled(PrimitiveStyle::with_stroke(pale, 1))
            .draw(c);
        let _ =
            Text::with_alignment(&label(x), p + Point::new(0, 14), text, Alignment::Center).draw(c);
        x += sx;
    }
    let mut y = 0.0;
    while y <= fmax {
        let p = at(0.0, y);
        let _ = Line::new(p, at(xmax, y))
            .into_styled(PrimitiveStyle::with_stroke(pale, 1))
            .draw(c);
        let _ =
            Text::with_alignment(&label(y), p + Point::new(-4, 4), text, Alignment::Right).draw(c);
        y += sy;
    }
    let _ = Rectangle::with_corners(at(0.0, fmax), at(xmax, 0.0))
        .into_styled(PrimitiveStyle::with_stroke(ink, 1))
        .draw(c);
    // the per-revolution excitation lines 1× and 2× (f = kΩ/2π), dashed grey
    for k in [1.0, 2.0] {
        let end = (fmax * TAU / k).min(xmax);
        let n = 60;
        for i in (0..n).step_by(2) {
            let (a, b) = (end * i as f64 / n as f64, end * (i + 1) as f64 / n as f64);
            let _ = Line::new(at(a, k * a / TAU), at(b, k * b / TAU))
                .into_styled(PrimitiveStyle::with_stroke(Rgb888::new(120, 120, 120), 1))
                .draw(c);
        }
        let p = at(end, k * end / TAU);
        let _ = Text::with_alignment(
            &format!("{}x", k as u32),
            p + Point::new(-4, 14),
            text,
            Alignment::Right,
        )
        .draw(c);
    }
    // the modes
    for m in 0..d.modes() {
        let colour = MODE_COLOURS[m % MODE_COLOURS.len()];
        let pts: Vec<Point> = d
            .speeds
            .iter()
            .zip(&d.frequencies)
            .filter_map(|(&w, f)| f.get(m).map(|&f| at(w, f)))
            .collect();
        for pair in pts.windows(2) {
            let _ = Line::new(pair[0], pair[1])
                .into_styled(PrimitiveStyle::with_stroke(colour, 2))
                .draw(c);
        }
        for &p in &pts {
            let _ = Circle::with_center(p, 5)
                .into_styled(PrimitiveStyle::with_fill(colour))
                .draw(c);
        }
    }
    let _ = Text::with_alignment(
        title,
        Point::new((w / 2.0) as i32, 18),
        text,
        Alignment::Center,
    )
    .draw(c);
    let _ = Text::with_alignment(
        "hub speed (rad/s)",
        Point::new(((left + right) / 2.0) as i32, (h - 8.0) as i32),
        text,
        Alignment::Center,
    )
    .draw(c);
    let _ = Text::new("Hz", Point::new(8, (top + 4.0) as i32), text).draw(c);
}

#[cfg(test)]
mod tests {
    use super::{parse_speeds, tick, Diagram};

    #[test]
    fn speeds_include_both_ends() {
        assert_eq!(parse_speeds("0:10:3").unwrap(), [0.0, 5.0, 10.0]);
        assert!(parse_speeds("0:10").is_err());
        assert!(parse_speeds("5:1:3").is_err());
        assert!(parse_speeds("0:1:1").is_err());
    }

    #[test]
    fn ticks_are_round() {
        assert_eq!(tick(10.0), 2.0);
        assert_eq!(tick(0.9), 0.2);
        assert_eq!(tick(120.0), 25.0);
    }

    #[test]
    fn csv_leaves_missing_modes_empty() {
        let d = Diagram {
            speeds: vec![0.0, 1.0],
            frequencies: vec![vec![1.5, 2.5], vec![1.75]],
        };
        assert_eq!(
            d.csv(),
            "speed_rad_s,mode1_Hz,mode2_Hz\n0,1.5,2.5\n1,1.75,\n"
        );
    }
}
