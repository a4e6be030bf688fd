//! The study's work-precision chart as a PNG: estimated error against counted work, log-log,
//! one line per ladder, the target, the chosen setting and its finer check. Drawn with
//! `embedded-graphics` (as the animations are) on the charts' [`Canvas`].

use super::report::on_ladder;
use super::{Role, Study};
use crate::chart::Canvas;
use embedded_graphics::mono_font::{ascii::FONT_6X10, MonoTextStyle};
use embedded_graphics::pixelcolor::Rgb888;
use embedded_graphics::prelude::*;
use embedded_graphics::primitives::{Circle, Line, Polyline, PrimitiveStyle, Rectangle};
use embedded_graphics::text::{Alignment, Text};

const WIDTH: u32 = 720;
const HEIGHT: u32 = 480;
/// The plot area's margins: left, right, top, bottom.
const MARGIN: [i32; 4] = [70, 20, 40, 50];

const TIME: Rgb888 = Rgb888::new(31, 119, 180);
const MESH: Rgb888 = Rgb888::new(255, 127, 14);
const CHOSEN: Rgb888 = Rgb888::new(214, 39, 40);
const FINER: Rgb888 = Rgb888::new(44, 160, 44);
const GREY: Rgb888 = Rgb888::new(170, 170, 170);
const INK: Rgb888 = Rgb888::new(30, 30, 30);

/// Decades spanning `lo..hi` (positive), at least one.
fn decades(lo: f64, hi: f64) -> (i32, i32) {
    let a = lo.log10().floor() as i32;
    let b = (hi.log10().ceil() as i32).max(a + 1);
    (a, b)
}

/// The chart as PNG bytes.
pub fn png(study: &Study) -> Vec<u8> {
    let mut c = Canvas::new(WIDTH, HEIGHT);
    let pts: Vec<(f64, f64, Role)> = study
        .runs
        .iter()
        .filter(|r| on_ladder(r))
        .filter_map(|r| Some((r.work.max(1e-6), r.error()?.max(1e-16), r.role)))
        .collect();
    let (mut xlo, mut xhi, mut ylo, mut yhi) = (f64::MAX, 0.0_f64, study.target, study.target);
    for &(x, y, _) in &pts {
        xlo = xlo.min(x);
        xhi = xhi.max(x);
        ylo = ylo.min(y);
        yhi = yhi.max(y);
    }
    if pts.is_empty() {
        (xlo, xhi) = (1e-3, 1.0);
    }
    let (x0, x1) = decades(xlo, xhi);
    let (y0, y1) = decades(ylo, yhi);
    let [ml, mr, mt, mb] = MARGIN;
    let (w, h) = (WIDTH as i32 - ml - mr, HEIGHT as i32 - mt - mb);
    let px = |x: f64| ml + ((x.log10() - x0 as f64) / (x1 - x0) as f64 * w as f64).round() as i32;
    let py =
        |y: f64| mt + h - ((y.log10() - y0 as f64) / (y1 - y0) as f64 * h as f64).round() as i32;
    let text = MonoTextStyle::new(&FONT_6X10, INK);
    let thin = |col| PrimitiveStyle::with_stroke(col, 1);
    // the grid and its labels, a line per decade
    for d in x0..=x1 {
        let x = px(10f64.powi(d));
        let _ = Line::new(Point::new(x, mt), Point::new(x, mt + h))
            .into_styled(thin(GREY))
            .draw(&mut c);
        let _ = Text::with_alignment(
            &format!("1e{d}"),
            Point::new(x, mt + h + 14),
            text,
            Alignment::Center,
        )
        .draw(&mut c);
    }
    for d in y0..=y1 {
        let y = py(10f64.powi(d));
        let _ = Line::new(Point::new(ml, y), Point::new(ml + w, y))
            .into_styled(thin(GREY))
            .draw(&mut c);
        let _ = Text::with_alignment(
            &format!("1e{d}"),
            Point::new(ml - 6, y + 3),
            text,
            Alignment::Right,
        )
        .draw(&mut c);
    }
    let _ = Rectangle::new(Point::new(ml, mt), Size::new(w as u32, h as u32))
        .into_styled(thin(INK))
        .draw(&mut c);
    let _ = Text::with_alignment(
        "counted work of a run (about CPU s)",
        Point::new(ml + w / 2, HEIGHT as i32 - 12),
        text,
        Alignment::Center,
    )
    .draw(&mut c);
    let _ = Text::new("estimated error", Point::new(4, mt - 8), text).draw(&mut c);
    let title = format!(
        "{}: {} (target {:.0e})",
        study.scene,
        study.outputs.join(", "),
        study.target
    );
    let _ = Text::with_alignment(&title, Point::new(ml + w / 2, 16), text, Alignment::Center)
        .draw(&mut c);
    // the target, dashed
    let yt = py(study.target);
    let mut x = ml;
    while x < ml + w {
        let _ = Line::new(Point::new(x, yt), Point::new((x + 6).min(ml + w), yt))
            .into_styled(PrimitiveStyle::with_stroke(CHOSEN, 1))
            .draw(&mut c);
        x += 12;
    }
    // the ladders, coarse to fine
    for (role, col) in [(Role::Time, TIME), (Role::Mesh, MESH)] {
        let mut line: Vec<Point> = Vec::new();
        if role == Role::Mesh {
            // the mesh ladder starts at the time ladder's run at its step
            if let Some(r) = study
                .runs
                .iter()
                .filter(|r| r.role == Role::Time)
                .nth(study.mesh_step_level)
            {
                if let Some(e) = r.error() {
                    line.push(Point::new(px(r.work.max(1e-6)), py(e.max(1e-16))));
                }
            }
        }
        line.extend(
            pts.iter()
                .filter(|p| p.2 == role)
                .map(|&(x, y, _)| Point::new(px(x), py(y))),
        );
        let _ = Polyline::new(&line)
            .into_styled(PrimitiveStyle::with_stroke(col, 2))
            .draw(&mut c);
        for p in &line {
            let _ = Circle::with_center(*p, 7)
                .into_styled(PrimitiveStyle::with_fill(col))
                .draw(&mut c);
        }
    }
    if let Some(ch) = &study.choice {
        let mut mark = |i: usize, col| {
            let r = &study.runs[i];
            if let Some(e) = r.error() {
                let p = Point::new(px(r.work.max(1e-6)), py(e.max(1e-16)));
                let _ = Circle::with_center(p, 15)
                    .into_styled(PrimitiveStyle::with_stroke(col, 2))
                    .draw(&mut c);
            }
        };
        mark(ch.run, CHOSEN);
        if let Some((i, _)) = ch.finer {
            mark(i, FINER);
        }
    }
    // the legend
    let legend = [
        (TIME, "time ladder"),
        (MESH, "mesh ladder"),
        (CHOSEN, "chosen / target"),
        (FINER, "finer check"),
    ];
    for (k, (col, name)) in legend.iter().enumerate() {
        let y = mt + 14 + 14 * k as i32;
        let _ = Circle::with_center(Point::new(ml + w - 130, y - 3), 7)
            .into_styled(PrimitiveStyle::with_fill(*col))
            .draw(&mut c);
        let _ = Text::new(name, Point::new(ml + w - 120, y), text).draw(&mut c);
    }
    c.png()
}
