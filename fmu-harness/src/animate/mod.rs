//! `fmu-harness animate`: a run drawn as it moved, for a person to look at.
//!
//! A run comes from a CSV that `simulate` or `cosim` wrote, from an FMU (run here with its
//! DefaultExperiment through [`crate::simulate`]) or from a scene file (run directly by the
//! engine). [`Motion::from_run`] finds the beams by their shape outputs
//! (`<beam>.shape.x[i]`, the unit's shape outputs) and, where a scene is known, the rigid bodies
//! and joints by their pose outputs. [`gif`] writes an animated GIF (the `gif` crate encodes,
//! `embedded-graphics` draws); [`html`] a self-contained page that plays the run with a time
//! slider, play/pause, speed, a deformation magnification and, in 3D, a view turned with the
//! mouse.
//!
//! Magnification: each beam's deformation is the offset of its points across the axis its
//! deflections are measured from (`<beam>.axis.*`: the root frame's axis, or the chord of a
//! pinned frame); only that offset is multiplied, never the rigid motion, so a beam's root
//! stays where it is. By default the factor makes the largest deflection of the run about
//! 10 % of its beam's length (a round number, never below 1).

mod bounds;
pub mod gif;
pub mod html;
mod source;
pub mod view;

pub use bounds::{
    check_frames, check_options, check_recorded_times, GIF_SIDES, MAX_FPS, MAX_FRAMES,
    MAX_GIF_PIXELS, MAX_RECORDED_TIMES,
};
pub use source::{
    known_scene, packaged_scene, planned_experiment, read_csv, run_fmu, run_scene, Recording,
};

use fmu_beam::scene::{JointKind, Scene};
use std::path::PathBuf;

/// Largest deflection shown, as a share of its beam's length, by the default magnification.
pub const SHOWN_DEFLECTION: f64 = 0.1;

#[derive(Debug, thiserror::Error)]
pub enum AnimateError {
    #[error("{}: {message}", .path.display())]
    Csv { path: PathBuf, message: String },
    #[error("{}: line {line}: {message}", .path.display())]
    CsvLine {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error(
        "the run has no shape outputs (`<beam>.shape.x[i]`): nothing to draw; package the scene \
         with this version and record every output"
    )]
    NoShape,
    #[error("beam `{beam}`: column `{column}` is missing")]
    MissingColumn { beam: String, column: String },
    #[error("the run has {rows} recorded time(s): at least 2 are needed")]
    TooShort { rows: usize },
    #[error("times must increase: row {row} has t = {t} after {previous}")]
    TimeNotIncreasing { row: usize, t: f64, previous: f64 },
    #[error("{name} = {value}: {rule}")]
    BadOption {
        name: &'static str,
        value: String,
        rule: &'static str,
    },
    #[error("{}: writing the GIF: {message}", .path.display())]
    Gif { path: PathBuf, message: String },
    #[error("scene `{origin}` for the run: {message}")]
    Scene { origin: String, message: String },
    /// The GIF would have too many frames or pixels, or none (issue 45): refused before
    /// the run is made or drawn.
    #[error(
        "--speed {speed:e} and --fps {fps}: the GIF would have {frames:.4e} frames of \
         {width} x {height} pixels ({span:e} s of run); {rule}"
    )]
    Frames {
        frames: f64,
        span: f64,
        fps: f64,
        speed: f64,
        width: u32,
        height: u32,
        rule: String,
    },
    /// A run made here would record too many times (issue 45).
    #[error(
        "--stop {stop:e} and --step {step:e}: the run would record {times:.4e} times from \
         {start:e} s; animate records at most {limit:e} recorded times: give a larger --step \
         or a shorter --stop"
    )]
    TooManyTimes {
        start: f64,
        stop: f64,
        step: f64,
        times: f64,
        limit: f64,
    },
}

/// One beam's motion: `n` points per recorded time (world x, y, z) and its deflection axis.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamTrack {
    pub name: String,
    pub n: usize,
    /// [time][point][xyz], flattened.
    pub points: Vec<f64>,
    /// [time][xyz]: unit direction the deflection is measured from.
    pub axis: Vec<f64>,
    /// Undeformed length: the polyline's length at the first time.
    pub length: f64,
}

/// A rigid body's pose per recorded time: position and rotation (body → world, row-major).
#[derive(Debug, Clone, PartialEq)]
pub struct BodyTrack {
    pub name: String,
    pub position: Vec<f64>,
    pub rotation: Vec<f64>,
}

/// A joint's position per recorded time and what it is.
#[derive(Debug, Clone, PartialEq)]
pub struct JointTrack {
    pub name: String,
    /// `revolute`, `prismatic`, `weld`, `spherical`.
    pub kind: &'static str,
    /// Held to the world (one of its frames is `world`).
    pub grounded: bool,
    pub position: Vec<f64>,
    /// A prismatic joint on the world: its sliding direction (world).
    pub rail: Option<[f64; 3]>,
}

/// What is drawn: the parts of the run at each of its recorded times.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    pub title: String,
    /// 2 or 3.
    pub dims: usize,
    pub times: Vec<f64>,
    pub beams: Vec<BeamTrack>,
    pub bodies: Vec<BodyTrack>,
    pub joints: Vec<JointTrack>,
}

/// A scene whose outputs are in the run, their names prefixed by `prefix` (a cosim unit's
/// name and a dot, or nothing).
#[derive(Debug, Clone)]
pub struct KnownScene {
    pub prefix: String,
    pub scene: Scene,
}

impl Motion {
    /// The parts found in a recording: every beam with shape outputs, and the bodies and joints
    /// of the known scenes whose pose outputs were recorded.
    pub fn from_run(
        run: &Recording,
        scenes: &[KnownScene],
        title: &str,
    ) -> Result<Motion, AnimateError> {
        let times = run.column("time").unwrap_or_default();
        if times.len() < 2 {
            return Err(AnimateError::TooShort { rows: times.len() });
        }
        for (row, w) in times.windows(2).enumerate() {
            if w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) {
                return Err(AnimateError::TimeNotIncreasing {
                    row: row + 1,
                    t: w[1],
                    previous: w[0],
                });
            }
        }
        let rows = times.len();
        let mut beams = Vec::new();
        let mut dims = 2;
        for (prefix, n) in shape_prefixes(&run.columns) {
            let col = |name: String| run.column(&name);
            let need = |name: String| {
                col(name.clone()).ok_or(AnimateError::MissingColumn {
                    beam: prefix.clone(),
                    column: name,
                })
            };
            let has_z = col(format!("{prefix}.shape.z[1]")).is_some();
            if has_z {
                dims = 3;
            }
            let mut coords = Vec::new();
            for c in ["x", "y", "z"] {
                let mut per = Vec::new();
                for i in 1..=n {
                    per.push(if c == "z" && !has_z {
                        vec![0.0; rows]
                    } else {
                        need(format!("{prefix}.shape.{c}[{i}]"))?
                    });
                }
                coords.push(per);
            }
            let mut points = Vec::with_capacity(rows * n * 3);
            for r in 0..rows {
                for i in 0..n {
                    for c in &coords {
                        points.push(c[i][r]);
                    }
                }
            }
            let axis_cols: Vec<Option<Vec<f64>>> = ["x", "y", "z"]
                .iter()
                .map(|c| col(format!("{prefix}.axis.{c}")))
                .collect();
            let mut axis = Vec::with_capacity(rows * 3);
            for r in 0..rows {
                let p = &points[r * n * 3..(r + 1) * n * 3];
                let chord = normalized([
                    p[3 * (n - 1)] - p[0],
                    p[3 * (n - 1) + 1] - p[1],
                    p[3 * (n - 1) + 2] - p[2],
                ]);
                let given = match &axis_cols[..] {
                    [Some(x), Some(y), z] => Some([x[r], y[r], z.as_ref().map_or(0.0, |z| z[r])]),
                    _ => None,
                };
                axis.extend(given.unwrap_or(chord));
            }
            let length = (1..n)
                .map(|i| {
                    (0..3)
                        .map(|k| (points[3 * i + k] - points[3 * (i - 1) + k]).powi(2))
                        .sum::<f64>()
                        .sqrt()
                })
                .sum();
            beams.push(BeamTrack {
                name: prefix,
                n,
                points,
                axis,
                length,
            });
        }
        if beams.is_empty() {
            return Err(AnimateError::NoShape);
        }
        let mut bodies = Vec::new();
        let mut joints = Vec::new();
        for known in scenes {
            if known.scene.is_3d() {
                dims = 3;
            }
            let p = &known.prefix;
            let xyz = |name: &str| -> Option<Vec<f64>> {
                let x = run.column(&format!("{p}{name}.x"))?;
                let y = run.column(&format!("{p}{name}.y"))?;
                let z = run
                    .column(&format!("{p}{name}.z"))
                    .unwrap_or(vec![0.0; rows]);
                Some((0..rows).flat_map(|r| [x[r], y[r], z[r]]).collect())
            };
            for b in &known.scene.bodies {
                let Some(position) = xyz(&b.name) else {
                    continue;
                };
                let rotation = if let Some(phi) = run.column(&format!("{p}{}.phi", b.name)) {
                    phi.iter()
                        .flat_map(|a| {
                            let (s, c) = a.sin_cos();
                            [c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0]
                        })
                        .collect()
                } else {
                    let entries: Option<Vec<Vec<f64>>> = (1..=3)
                        .flat_map(|i| (1..=3).map(move |j| (i, j)))
                        .map(|(i, j)| run.column(&format!("{p}{}.R[{i},{j}]", b.name)))
                        .collect();
                    match entries {
                        Some(e) => (0..rows)
                            .flat_map(|r| e.iter().map(move |c| c[r]))
                            .collect(),
                        None => (0..rows)
                            .flat_map(|_| [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])
                            .collect(),
                    }
                };
                bodies.push(BodyTrack {
                    name: format!("{p}{}", b.name),
                    position,
                    rotation,
                });
            }
            for j in &known.scene.joints {
                let Some(position) = xyz(&j.name) else {
                    continue;
                };
                let grounded = j.frames.iter().any(|f| f == "world");
                let rail = (j.kind == JointKind::Prismatic && j.frames[0] == "world").then(|| {
                    j.axis.unwrap_or_else(|| {
                        let (s, c) = j.axis_angle.sin_cos();
                        [c, s, 0.0]
                    })
                });
                joints.push(JointTrack {
                    name: format!("{p}{}", j.name),
                    kind: match j.kind {
                        JointKind::Revolute => "revolute",
                        JointKind::Prismatic => "prismatic",
                        JointKind::Weld => "weld",
                        JointKind::Spherical => "spherical",
                    },
                    grounded,
                    rail,
                    position,
                });
            }
        }
        Ok(Motion {
            title: title.to_string(),
            dims,
            times,
            beams,
            bodies,
            joints,
        })
    }

    /// Largest deflection over the run relative to its beam's length (0 for straight beams).
    pub fn largest_deflection_ratio(&self) -> f64 {
        let mut worst: f64 = 0.0;
        for b in &self.beams {
            if b.length <= 0.0 {
                continue;
            }
            for r in 0..self.times.len() {
                let a = &b.axis[3 * r..3 * r + 3];
                let p = &b.points[r * b.n * 3..(r + 1) * b.n * 3];
                for i in 0..b.n {
                    let d = across(&p[3 * i..3 * i + 3], &p[0..3], a);
                    worst = worst.max(norm(d) / b.length);
                }
            }
        }
        worst
    }

    /// The default magnification: the largest deflection shown as about
    /// [`SHOWN_DEFLECTION`] of its beam's length, rounded down to 1, 2 or 5 × 10^k, at least 1.
    pub fn auto_magnification(&self) -> f64 {
        let r = self.largest_deflection_ratio();
        if r <= 0.0 || r >= SHOWN_DEFLECTION {
            return 1.0;
        }
        round_down(SHOWN_DEFLECTION / r).max(1.0)
    }

    /// Points of beam `b` at recorded time `r` with the deformation magnified `m` times.
    pub fn beam_points(&self, b: usize, r: usize, m: f64) -> Vec<[f64; 3]> {
        let beam = &self.beams[b];
        let p = &beam.points[r * beam.n * 3..(r + 1) * beam.n * 3];
        let a = &beam.axis[3 * r..3 * r + 3];
        (0..beam.n)
            .map(|i| magnified(&p[3 * i..3 * i + 3], &p[0..3], a, m))
            .collect()
    }

    /// The motion at the given times, each interpolated linearly between the recorded times
    /// around it (times outside the run take its ends).
    pub fn resampled(&self, at: &[f64]) -> Motion {
        let t = &self.times;
        let weights: Vec<(usize, usize, f64)> = at
            .iter()
            .map(|&x| {
                let k = t.partition_point(|&s| s <= x);
                if k == 0 {
                    (0, 0, 0.0)
                } else if k >= t.len() {
                    (t.len() - 1, t.len() - 1, 0.0)
                } else {
                    (k - 1, k, (x - t[k - 1]) / (t[k] - t[k - 1]))
                }
            })
            .collect();
        let mix = |v: &[f64], width: usize| -> Vec<f64> {
            let mut out = Vec::with_capacity(at.len() * width);
            for &(a, b, w) in &weights {
                for k in 0..width {
                    out.push(v[a * width + k] * (1.0 - w) + v[b * width + k] * w);
                }
            }
            out
        };
        Motion {
            title: self.title.clone(),
            dims: self.dims,
            times: at.to_vec(),
            beams: self
                .beams
                .iter()
                .map(|b| BeamTrack {
                    points: mix(&b.points, 3 * b.n),
                    axis: mix(&b.axis, 3)
                        .chunks(3)
                        .flat_map(|a| normalized([a[0], a[1], a[2]]))
                        .collect(),
                    ..b.clone()
                })
                .collect(),
            bodies: self
                .bodies
                .iter()
                .map(|b| BodyTrack {
                    position: mix(&b.position, 3),
                    rotation: mix(&b.rotation, 9),
                    ..b.clone()
                })
                .collect(),
            joints: self
                .joints
                .iter()
                .map(|j| JointTrack {
                    position: mix(&j.position, 3),
                    ..j.clone()
                })
                .collect(),
        }
    }

    /// Frame times from the run's start at `fps` frames per second of playback, `speed`
    /// simulated seconds per second of playback.
    pub fn frame_times(&self, fps: f64, speed: f64) -> Vec<f64> {
        let (t0, t1) = (self.times[0], *self.times.last().unwrap_or(&0.0));
        let dt = speed / fps;
        let count = ((t1 - t0) / dt * (1.0 + 1e-12)).floor() as usize + 1;
        (0..count).map(|k| t0 + k as f64 * dt).collect()
    }
}

/// The beams of a run: (prefix, points) of each `<prefix>.shape.x[1..n]`, in column order.
fn shape_prefixes(columns: &[String]) -> Vec<(String, usize)> {
    let mut found: Vec<(String, usize)> = Vec::new();
    for c in columns {
        let Some((prefix, rest)) = c.split_once(".shape.x[") else {
            continue;
        };
        let Some(i) = rest.strip_suffix(']').and_then(|s| s.parse::<usize>().ok()) else {
            continue;
        };
        match found.iter_mut().find(|(p, _)| p == prefix) {
            Some((_, n)) => *n = (*n).max(i),
            None => found.push((prefix.to_string(), i)),
        }
    }
    found.retain(|(_, n)| *n >= 2);
    found
}

/// The offset of p from the line through `root` along unit `axis`.
fn across(p: &[f64], root: &[f64], axis: &[f64]) -> [f64; 3] {
    let d = [p[0] - root[0], p[1] - root[1], p[2] - root[2]];
    let along = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2];
    [
        d[0] - along * axis[0],
        d[1] - along * axis[1],
        d[2] - along * axis[2],
    ]
}

/// p with its offset across the axis multiplied by m.
pub fn magnified(p: &[f64], root: &[f64], axis: &[f64], m: f64) -> [f64; 3] {
    let off = across(p, root, axis);
    [
        p[0] + (m - 1.0) * off[0],
        p[1] + (m - 1.0) * off[1],
        p[2] + (m - 1.0) * off[2],
    ]
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn normalized(v: [f64; 3]) -> [f64; 3] {
    let n = norm(v);
    if n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        [1.0, 0.0, 0.0]
    }
}

/// The largest of 1, 2, 5 × 10^k not above x (x > 0).
pub fn round_down(x: f64) -> f64 {
    let p = 10f64.powf(x.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|v| *v <= x * (1.0 + 1e-12))
        .unwrap_or(p)
}

/// What `animate` writes and how.
#[derive(Debug, Clone)]
pub struct Options {
    pub html: Option<PathBuf>,
    pub gif: Option<PathBuf>,
    /// Where to write the GIF's geometry (frame times, world → pixel map) as JSON.
    pub metadata: Option<PathBuf>,
    pub fps: f64,
    pub speed: f64,
    pub magnification: Option<f64>,
    pub width: u32,
    pub height: u32,
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    pub path: PathBuf,
    pub bytes: u64,
    pub seconds: f64,
    pub frames: usize,
}

/// Writes the page and the GIF that `options` ask for.
pub fn write(
    motion: &Motion,
    options: &Options,
) -> Result<(f64, Vec<Written>), crate::HarnessError> {
    check_options(options)?;
    let span = match (motion.times.first(), motion.times.last()) {
        (Some(a), Some(b)) => b - a,
        _ => 0.0,
    };
    check_frames(span, options)?;
    let magnification = options
        .magnification
        .unwrap_or_else(|| motion.auto_magnification());
    let mut written = Vec::new();
    if let Some(path) = &options.gif {
        let started = std::time::Instant::now();
        let frames = motion.resampled(&motion.frame_times(options.fps, options.speed));
        let size = (options.width, options.height);
        let view = view::View::fit(&frames, magnification, size);
        let count = gif::write(&frames, &view, magnification, options, path)?;
        if let Some(meta) = &options.metadata {
            let text = view.metadata(&frames, magnification, options.fps);
            crate::output_file::write_atomically(meta, text.as_bytes())?;
        }
        written.push(Written {
            path: path.clone(),
            bytes: file_size(path),
            seconds: started.elapsed().as_secs_f64(),
            frames: count,
        });
    }
    if let Some(path) = &options.html {
        let started = std::time::Instant::now();
        let text = html::page(motion, magnification, options.speed);
        crate::output_file::write_atomically(path, text.as_bytes())?;
        written.push(Written {
            path: path.clone(),
            bytes: text.len() as u64,
            seconds: started.elapsed().as_secs_f64(),
            frames: html::page_times(motion).len(),
        });
    }
    Ok((magnification, written))
}

fn file_size(path: &std::path::Path) -> u64 {
    std::fs::metadata(path).map(|m| m.len()).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_down_picks_1_2_5() {
        assert_eq!(round_down(7.3), 5.0);
        assert_eq!(round_down(19.9), 10.0);
        assert_eq!(round_down(20.0), 20.0);
        assert_eq!(round_down(0.031), 0.02);
    }

    #[test]
    fn magnification_leaves_the_axis_and_multiplies_the_offset() {
        let p = magnified(&[2.0, 0.5, 0.0], &[1.0, 0.0, 0.0], &[1.0, 0.0, 0.0], 10.0);
        assert_eq!(p, [2.0, 5.0, 0.0]);
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let p = magnified(&[1.0, 1.0, 0.0], &[0.0, 0.0, 0.0], &[s, s, 0.0], 3.0);
        assert!((p[0] - 1.0).abs() < 1e-15 && (p[1] - 1.0).abs() < 1e-15);
    }
}
