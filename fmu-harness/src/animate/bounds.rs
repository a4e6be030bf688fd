//! What an animation may cost, checked before the work (issue 45): frames per second, frames,
//! pixels of the GIF and recorded times of a run made here. `--speed 1e-17` aborted on a
//! 2e18-byte allocation, `--fps 1e9` after 3.9 GB, `--speed 1e-300` wrote a GIF of 0 frames.

use super::{AnimateError, Options};

/// Frames per second of playback a GIF can show: its delays count hundredths of a second.
pub const MAX_FPS: f64 = 100.0;
/// Frames of one GIF: 10 000 (400 s of playback at 25 fps).
pub const MAX_FRAMES: f64 = 10_000.0;
/// Pixels drawn for one GIF, frames × width × height: 10 000 frames of 640 × 480.
pub const MAX_GIF_PIXELS: f64 = 3.072e9;
/// Recorded times of a run `animate` makes itself (scene or FMU): 1e6, a hundred times the
/// GIF's frames at the most (the page keeps at most [`super::html::MAX_PAGE_TIMES`]).
pub const MAX_RECORDED_TIMES: f64 = 1e6;
/// Side of a GIF frame in pixels, least and most.
pub const GIF_SIDES: std::ops::RangeInclusive<u32> = 16..=4096;

/// The options' own bounds, before anything is run: frames per second in (0, [`MAX_FPS`]],
/// a positive finite speed and magnification, each side of the GIF in [`GIF_SIDES`].
pub fn check_options(options: &Options) -> Result<(), AnimateError> {
    let check = |name: &'static str, v: f64, ok: bool, rule: &'static str| {
        if ok && v.is_finite() {
            Ok(())
        } else {
            Err(AnimateError::BadOption {
                name,
                value: v.to_string(),
                rule,
            })
        }
    };
    check(
        "--fps",
        options.fps,
        options.fps > 0.0 && options.fps <= MAX_FPS,
        "must be positive and at most 100 (a GIF's delays count hundredths of a second)",
    )?;
    check(
        "--speed",
        options.speed,
        options.speed > 0.0,
        "must be positive",
    )?;
    if let Some(m) = options.magnification {
        check("--magnify", m, m > 0.0, "must be positive (1: true scale)")?;
    }
    let (w, h) = (options.width, options.height);
    if options.gif.is_some() && !(GIF_SIDES.contains(&w) && GIF_SIDES.contains(&h)) {
        return Err(AnimateError::BadOption {
            name: "--size",
            value: format!("{w}x{h}"),
            rule: "each side from 16 to 4096 pixels",
        });
    }
    Ok(())
}

/// The number of GIF frames of a run of `span` seconds (none without a GIF), refused when
/// not between 1 and [`MAX_FRAMES`] (a speed of 1e-300 made 0 by overflow) or over
/// [`MAX_GIF_PIXELS`]: known from the options and
/// the run's span, before the run is made or a frame drawn.
pub fn check_frames(span: f64, options: &Options) -> Result<usize, AnimateError> {
    if options.gif.is_none() {
        return Ok(0);
    }
    let frames = (span * options.fps / options.speed * (1.0 + 1e-12)).floor() + 1.0;
    let pixels = frames * f64::from(options.width) * f64::from(options.height);
    let refuse = |rule: String| AnimateError::Frames {
        frames,
        span,
        fps: options.fps,
        speed: options.speed,
        width: options.width,
        height: options.height,
        rule,
    };
    if !(frames.is_finite() && frames <= MAX_FRAMES) {
        return Err(refuse(format!(
            "at most {MAX_FRAMES} frames: give a larger --speed or a smaller --fps"
        )));
    }
    if frames < 1.0 {
        return Err(refuse("at least 1 frame".into()));
    }
    if pixels > MAX_GIF_PIXELS {
        return Err(refuse(format!(
            "{pixels:.3e} pixels, at most {MAX_GIF_PIXELS:e}: give a smaller --size, a larger \
             --speed or a smaller --fps"
        )));
    }
    Ok(frames as usize)
}

/// The recorded times of a run from `start` to `stop` every `step` s, refused above
/// [`MAX_RECORDED_TIMES`] (or when not a number) before the run is made.
pub fn check_recorded_times(start: f64, stop: f64, step: f64) -> Result<(), AnimateError> {
    let times = ((stop - start) / step).ceil() + 1.0;
    if times.is_nan() || times > MAX_RECORDED_TIMES {
        return Err(AnimateError::TooManyTimes {
            start,
            stop,
            step,
            times,
            limit: MAX_RECORDED_TIMES,
        });
    }
    Ok(())
}
