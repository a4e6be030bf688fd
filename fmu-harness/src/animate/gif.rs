//! The animated GIF: each frame drawn with `embedded-graphics` (lines, circles, polylines, a
//! monospaced font) into a palette-indexed buffer, encoded by the `gif` crate; a frame after
//! the first carries only the rectangle that changed.

use super::view::View;
use super::{AnimateError, Motion, Options};
use embedded_graphics::mono_font::{ascii::FONT_7X13, MonoTextStyle};
use embedded_graphics::pixelcolor::PixelColor;
use embedded_graphics::prelude::*;
use embedded_graphics::primitives::{
    Circle, Line, Polyline, PrimitiveStyle, PrimitiveStyleBuilder, Triangle,
};
use embedded_graphics::text::{Alignment, Text};
use std::borrow::Cow;
use std::path::Path;

/// A palette index.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ink(pub u8);

impl PixelColor for Ink {
    type Raw = ();
}

const WHITE: Ink = Ink(0);
const TEXT: Ink = Ink(1);
const PALE: Ink = Ink(2);
const AXES: [Ink; 3] = [Ink(3), Ink(4), Ink(5)];
const DARK: Ink = Ink(6);
const BODY: Ink = Ink(7);
const FIRST_BEAM: u8 = 8;

/// The palette (RGB): background, text, pale grey, world x, y, z, joints, bodies, then the
/// beams' colours.
const PALETTE: [[u8; 3]; 16] = [
    [255, 255, 255],
    [40, 40, 40],
    [190, 190, 190],
    [200, 40, 40],
    [40, 150, 40],
    [40, 70, 200],
    [25, 25, 25],
    [150, 150, 150],
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [23, 190, 207],
    [188, 189, 34],
];

/// The colour (RGB) of the k-th beam, in the GIF and on the page.
pub fn beam_rgb(k: usize) -> [u8; 3] {
    PALETTE[FIRST_BEAM as usize + k % (PALETTE.len() - FIRST_BEAM as usize)]
}

fn beam_ink(k: usize) -> Ink {
    Ink(FIRST_BEAM + (k % (PALETTE.len() - FIRST_BEAM as usize)) as u8)
}

/// A frame: one palette index per pixel.
struct Canvas {
    width: u32,
    height: u32,
    pixels: Vec<u8>,
}

impl OriginDimensions for Canvas {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl DrawTarget for Canvas {
    type Color = Ink;
    type Error = std::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Ink>>>(
        &mut self,
        pixels: I,
    ) -> Result<(), Self::Error> {
        for Pixel(p, c) in pixels {
            if p.x >= 0 && p.y >= 0 && (p.x as u32) < self.width && (p.y as u32) < self.height {
                self.pixels[p.y as usize * self.width as usize + p.x as usize] = c.0;
            }
        }
        Ok(())
    }
}

fn at(p: [f64; 2]) -> Point {
    Point::new(p[0].round() as i32, p[1].round() as i32)
}

/// Draws every frame of `frames` and writes the GIF to `path`, whole or not at all
/// ([`crate::output_file::write_through_temporary`]); returns the number of frames.
pub fn write(
    frames: &Motion,
    view: &View,
    magnification: f64,
    options: &Options,
    path: &Path,
) -> Result<usize, crate::HarnessError> {
    crate::output_file::write_through_temporary(path, "writing the GIF", |out| {
        encode(frames, view, magnification, options, path, out)
    })
}

/// [`write`] into `out`; `path` names the GIF in messages.
fn encode(
    frames: &Motion,
    view: &View,
    magnification: f64,
    options: &Options,
    path: &Path,
    out: impl std::io::Write,
) -> Result<usize, crate::HarnessError> {
    let fail = |message: String| AnimateError::Gif {
        path: path.into(),
        message,
    };
    let (w, h) = (view.width, view.height);
    if !super::GIF_SIDES.contains(&w) || !super::GIF_SIDES.contains(&h) {
        return Err(AnimateError::BadOption {
            name: "--size",
            value: format!("{w}x{h}"),
            rule: "each side from 16 to 4096 pixels",
        }
        .into());
    }
    let palette: Vec<u8> = PALETTE.iter().flatten().copied().collect();
    let mut enc =
        gif::Encoder::new(out, w as u16, h as u16, &palette).map_err(|e| fail(e.to_string()))?;
    enc.set_repeat(gif::Repeat::Infinite)
        .map_err(|e| fail(e.to_string()))?;
    let statics = Statics::of(frames, view);
    let mut previous: Option<Vec<u8>> = None;
    let mut canvas = Canvas {
        width: w,
        height: h,
        pixels: vec![0; (w * h) as usize],
    };
    let centis = |k: usize| (k as f64 * 100.0 / options.fps).round() as u64;
    for r in 0..frames.times.len() {
        canvas.pixels.fill(WHITE.0);
        draw_frame(&mut canvas, frames, view, &statics, magnification, r);
        let delay = (centis(r + 1) - centis(r)).clamp(1, u16::MAX as u64) as u16;
        let (left, top, fw, fh) = match &previous {
            None => (0, 0, w, h),
            Some(prev) => changed(prev, &canvas.pixels, w, h),
        };
        let mut sub = Vec::with_capacity((fw * fh) as usize);
        for y in top..top + fh {
            let row = (y * w) as usize;
            sub.extend_from_slice(&canvas.pixels[row + left as usize..row + (left + fw) as usize]);
        }
        let frame = gif::Frame {
            delay,
            dispose: gif::DisposalMethod::Keep,
            left: left as u16,
            top: top as u16,
            width: fw as u16,
            height: fh as u16,
            buffer: Cow::Owned(sub),
            ..Default::default()
        };
        enc.write_frame(&frame).map_err(|e| fail(e.to_string()))?;
        previous = Some(canvas.pixels.clone());
    }
    enc.into_inner().map_err(|e| fail(e.to_string()))?;
    Ok(frames.times.len())
}

/// The smallest rectangle (left, top, width, height) holding every changed pixel (1 × 1 when
/// nothing changed).
fn changed(a: &[u8], b: &[u8], w: u32, h: u32) -> (u32, u32, u32, u32) {
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for y in 0..h {
        let row = (y * w) as usize;
        for x in 0..w {
            if a[row + x as usize] != b[row + x as usize] {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    if x0 > x1 {
        (0, 0, 1, 1)
    } else {
        (x0, y0, x1 - x0 + 1, y1 - y0 + 1)
    }
}

/// What every frame draws the same: the scale bar's length, the prismatic rails' extents.
struct Statics {
    bar: f64,
    /// Per joint with a rail: the two ends of the rail (world).
    rails: Vec<Option<([f64; 3], [f64; 3])>>,
}

impl Statics {
    fn of(frames: &Motion, view: &View) -> Statics {
        let bar =
            super::round_down(0.25 * (view.width as f64 - 2.0 * super::view::SIDE) / view.scale);
        let rails = frames
            .joints
            .iter()
            .map(|j| {
                let a = j.rail?;
                let along: Vec<f64> = j
                    .position
                    .chunks(3)
                    .map(|p| p[0] * a[0] + p[1] * a[1] + p[2] * a[2])
                    .collect();
                let lo = along.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = along.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let pad = 0.1 * (hi - lo) + 12.0 / view.scale;
                let p0 = &j.position[0..3];
                let base: [f64; 3] = std::array::from_fn(|k| p0[k] - along[0] * a[k]);
                let end = |s: f64| -> [f64; 3] { std::array::from_fn(|k| base[k] + s * a[k]) };
                Some((end(lo - pad), end(hi + pad)))
            })
            .collect();
        Statics { bar, rails }
    }
}

fn draw_frame(c: &mut Canvas, m: &Motion, view: &View, s: &Statics, mag: f64, r: usize) {
    let thin = |ink| PrimitiveStyle::with_stroke(ink, 1);
    let text = MonoTextStyle::new(&FONT_7X13, TEXT);
    let _ = Text::new(&m.title, Point::new(8, 16), text).draw(c);
    let _ = Text::with_alignment(
        &format!("t = {:.3} s", m.times[r]),
        Point::new(view.width as i32 - 8, 16),
        text,
        Alignment::Right,
    )
    .draw(c);
    // the world frame at the origin
    let o = view.px([0.0; 3]);
    let axis_len = 36.0;
    for k in 0..m.dims {
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let tip = view.px(e);
        let d = [tip[0] - o[0], tip[1] - o[1]];
        let n = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-9);
        let end = [o[0] + axis_len * d[0] / n, o[1] + axis_len * d[1] / n];
        let _ = Line::new(at(o), at(end))
            .into_styled(PrimitiveStyle::with_stroke(AXES[k], 2))
            .draw(c);
        let label = [
            o[0] + (axis_len + 8.0) * d[0] / n - 3.0,
            o[1] + (axis_len + 8.0) * d[1] / n + 4.0,
        ];
        let _ = Text::new(
            ["x", "y", "z"][k],
            at(label),
            MonoTextStyle::new(&FONT_7X13, AXES[k]),
        )
        .draw(c);
    }
    // rails of prismatic joints on the world
    for rail in s.rails.iter().flatten() {
        let _ = Line::new(at(view.px(rail.0)), at(view.px(rail.1)))
            .into_styled(PrimitiveStyle::with_stroke(PALE, 3))
            .draw(c);
    }
    // beams, magnified
    for b in 0..m.beams.len() {
        let pts: Vec<Point> = m
            .beam_points(b, r, mag)
            .into_iter()
            .map(|p| at(view.px(p)))
            .collect();
        let _ = Polyline::new(&pts)
            .into_styled(PrimitiveStyle::with_stroke(beam_ink(b), 3))
            .draw(c);
    }
    // rigid bodies: a square along their axes (3D: their axes)
    for b in &m.bodies {
        let p = [
            b.position[3 * r],
            b.position[3 * r + 1],
            b.position[3 * r + 2],
        ];
        let rot = &b.rotation[9 * r..9 * r + 9];
        let centre = view.px(p);
        let half = 7.0;
        // the body axes' directions on screen, each `half` pixels long
        let dir = |k: usize| {
            let q = view.px([p[0] + rot[k], p[1] + rot[3 + k], p[2] + rot[6 + k]]);
            let d = [q[0] - centre[0], q[1] - centre[1]];
            let n = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-9);
            [half * d[0] / n, half * d[1] / n]
        };
        if m.dims == 2 {
            let (u, v) = (dir(0), dir(1));
            let corner = |a: f64, b: f64| {
                at([
                    centre[0] + a * u[0] + b * v[0],
                    centre[1] + a * u[1] + b * v[1],
                ])
            };
            let square = [
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
                corner(-1.0, -1.0),
            ];
            let _ = Polyline::new(&square)
                .into_styled(PrimitiveStyle::with_stroke(DARK, 2))
                .draw(c);
        } else {
            for k in 0..3 {
                let d = dir(k);
                let _ = Line::new(
                    at(centre),
                    at([centre[0] + 2.0 * d[0], centre[1] + 2.0 * d[1]]),
                )
                .into_styled(PrimitiveStyle::with_stroke(AXES[k], 2))
                .draw(c);
            }
            let _ = Circle::with_center(at(centre), 7)
                .into_styled(PrimitiveStyle::with_fill(BODY))
                .draw(c);
        }
    }
    // joints
    for j in &m.joints {
        let p = view.px([
            j.position[3 * r],
            j.position[3 * r + 1],
            j.position[3 * r + 2],
        ]);
        if j.grounded && j.kind != "prismatic" {
            // the ground symbol below a joint held to the world
            let _ = Triangle::new(
                at(p),
                at([p[0] - 7.0, p[1] + 11.0]),
                at([p[0] + 7.0, p[1] + 11.0]),
            )
            .into_styled(thin(DARK))
            .draw(c);
            let _ = Line::new(
                at([p[0] - 10.0, p[1] + 11.0]),
                at([p[0] + 10.0, p[1] + 11.0]),
            )
            .into_styled(PrimitiveStyle::with_stroke(DARK, 2))
            .draw(c);
        }
        let style = |fill| {
            PrimitiveStyleBuilder::new()
                .stroke_color(DARK)
                .stroke_width(2)
                .fill_color(fill)
                .build()
        };
        let _ = match j.kind {
            "revolute" => Circle::with_center(at(p), 9)
                .into_styled(style(WHITE))
                .draw(c),
            "spherical" => Circle::with_center(at(p), 9)
                .into_styled(style(DARK))
                .draw(c),
            "prismatic" => {
                let _ = Circle::with_center(at(p), 7)
                    .into_styled(style(BODY))
                    .draw(c);
                Ok(())
            }
            _ => embedded_graphics::primitives::Rectangle::with_center(at(p), Size::new(8, 8))
                .into_styled(style(DARK))
                .draw(c),
        };
    }
    // the length scale and the magnification
    let y = view.height as f64 - 18.0;
    let x0 = 12.0;
    let x1 = x0 + s.bar * view.scale;
    let _ = Line::new(at([x0, y]), at([x1, y]))
        .into_styled(PrimitiveStyle::with_stroke(TEXT, 2))
        .draw(c);
    for x in [x0, x1] {
        let _ = Line::new(at([x, y - 5.0]), at([x, y + 5.0]))
            .into_styled(thin(TEXT))
            .draw(c);
    }
    let _ = Text::new(&length_label(s.bar), at([x1 + 8.0, y + 4.0]), text).draw(c);
    let mag_text = if mag == 1.0 {
        "deformation: true scale".to_string()
    } else {
        format!("deformation x {}", number(mag))
    };
    let _ = Text::with_alignment(
        &mag_text,
        Point::new(view.width as i32 - 8, y as i32 + 4),
        text,
        Alignment::Right,
    )
    .draw(c);
}

/// A length for the scale bar: "0.05 m", "2 m".
pub fn length_label(l: f64) -> String {
    format!("{} m", number(l))
}

/// A round number without trailing zeros.
fn number(x: f64) -> String {
    let s = format!("{x:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
