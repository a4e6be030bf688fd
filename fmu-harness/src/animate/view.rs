//! The map from world coordinates to the pixels of a GIF frame: the whole run fits the frame
//! (2D: x to the right, y up; 3D: an orthographic view from a fixed azimuth and elevation,
//! z up), with room for the text above and the length scale below.

use super::Motion;

/// The 3D view of the GIF: azimuth and elevation of the eye (degrees), as a person would
/// first look at a mechanism: from the front right, somewhat above.
pub const AZIMUTH: f64 = -60.0;
pub const ELEVATION: f64 = 25.0;
/// Pixels kept free at the top (title, time), bottom (scale bar) and sides.
pub const TOP: f64 = 30.0;
pub const BOTTOM: f64 = 44.0;
pub const SIDE: f64 = 24.0;

#[derive(Debug, Clone, PartialEq)]
pub struct View {
    pub width: u32,
    pub height: u32,
    /// pixel = rows · p + offset (p in metres, pixels from the top left corner).
    pub rows: [[f64; 3]; 2],
    pub offset: [f64; 2],
    /// Pixels per metre.
    pub scale: f64,
    pub dims: usize,
}

impl View {
    /// The view in which every drawn point of every frame (beams magnified `m` times, bodies,
    /// joints, the world origin) fits a `size` frame.
    pub fn fit(frames: &Motion, m: f64, size: (u32, u32)) -> View {
        let dims = frames.dims;
        let (right, up) = if dims == 3 {
            let (az, el) = (AZIMUTH.to_radians(), ELEVATION.to_radians());
            (
                [-az.sin(), az.cos(), 0.0],
                [-el.sin() * az.cos(), -el.sin() * az.sin(), el.cos()],
            )
        } else {
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
        };
        let dot = |a: &[f64; 3], p: &[f64; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        let mut lo = [0.0f64, 0.0];
        let mut hi = [0.0f64, 0.0];
        let mut add = |p: &[f64; 3]| {
            let s = [dot(&right, p), dot(&up, p)];
            for k in 0..2 {
                lo[k] = lo[k].min(s[k]);
                hi[k] = hi[k].max(s[k]);
            }
        };
        for r in 0..frames.times.len() {
            for b in 0..frames.beams.len() {
                frames.beam_points(b, r, m).iter().for_each(&mut add);
            }
            for j in &frames.joints {
                add(&[
                    j.position[3 * r],
                    j.position[3 * r + 1],
                    j.position[3 * r + 2],
                ]);
            }
            for b in &frames.bodies {
                add(&[
                    b.position[3 * r],
                    b.position[3 * r + 1],
                    b.position[3 * r + 2],
                ]);
            }
        }
        let (w, h) = (size.0 as f64, size.1 as f64);
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9);
        let span = [
            (hi[0] - lo[0]).max(0.05 * extent),
            (hi[1] - lo[1]).max(0.05 * extent),
        ];
        let scale = ((w - 2.0 * SIDE) / span[0]).min((h - TOP - BOTTOM) / span[1]);
        let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
        let mid = [w / 2.0, TOP + (h - TOP - BOTTOM) / 2.0];
        View {
            width: size.0,
            height: size.1,
            rows: [
                [scale * right[0], scale * right[1], scale * right[2]],
                [-scale * up[0], -scale * up[1], -scale * up[2]],
            ],
            offset: [mid[0] - scale * centre[0], mid[1] + scale * centre[1]],
            scale,
            dims,
        }
    }

    /// The pixel (x right, y down; fractional) of world point p.
    pub fn px(&self, p: [f64; 3]) -> [f64; 2] {
        let r = &self.rows;
        [
            r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2] + self.offset[0],
            r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2] + self.offset[1],
        ]
    }

    /// The GIF's geometry as JSON: frame times, the magnification, the world → pixel map.
    pub fn metadata(&self, frames: &Motion, magnification: f64, fps: f64) -> String {
        serde_json::json!({
            "width": self.width,
            "height": self.height,
            "fps": fps,
            "magnification": magnification,
            "times": frames.times,
            "pixel_rows": self.rows,
            "pixel_offset": self.offset,
            "pixels_per_metre": self.scale,
            "beams": frames.beams.iter().map(|b| &b.name).collect::<Vec<_>>(),
            "beam_colors": (0..frames.beams.len()).map(super::gif::beam_rgb).collect::<Vec<_>>(),
        })
        .to_string()
    }
}
