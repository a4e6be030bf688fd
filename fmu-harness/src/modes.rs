//! `fmu-harness modes`: the scene's linearized natural frequencies with its joints free or
//! locked, at rest or at a hub speed, and its Campbell diagram (frequencies against speed) as
//! CSV and PNG.

pub mod campbell;

use crate::error::HarnessError;
use fmu_beam::{ModeOptions, Modes, Scene};
use std::path::Path;

/// The elastic natural frequencies (Hz, ascending) of the scene file, joints free, at rest.
pub fn elastic_frequencies(scene_path: &Path) -> Result<Vec<f64>, HarnessError> {
    let scene = Scene::load(scene_path)?;
    elastic_frequencies_of(&scene, &scene_path.display().to_string())
}

/// The elastic natural frequencies (Hz, ascending) of a loaded scene; `origin` (its file, or
/// what the caller names it) prefixes an error.
pub fn elastic_frequencies_of(scene: &Scene, origin: &str) -> Result<Vec<f64>, HarnessError> {
    Ok(modes_of(scene, origin, &ModeOptions::default())?.frequencies)
}

/// The modes of a loaded scene linearized as `options` say.
pub fn modes_of(scene: &Scene, origin: &str, options: &ModeOptions) -> Result<Modes, HarnessError> {
    fmu_beam::modes(scene, options).map_err(|source| HarnessError::Engine {
        origin: origin.to_string(),
        source,
    })
}

/// The report: what was linearized (speed and hub, locked joints, rigid-body modes left
/// out), then `mode <k>: <f> Hz` lines, k from 1, at most `count` of them, then the damped
/// modes where the scene has damping.
pub fn full_report(m: &Modes, count: usize) -> String {
    let mut s = String::new();
    match &m.hub {
        Some(h) if m.speed != 0.0 => {
            s += &format!(
            "linearized about the steady state at {} rad/s about hub '{h}' (co-rotating frame, \
             gyroscopic and centrifugal terms)\n",
            significant(m.speed, 6)
        )
        }
        Some(h) => s += &format!("linearized at rest, hub '{h}' held\n"),
        None if m.equilibrium => {
            s += "linearized at rest about the static equilibrium under gravity and the loads\n"
        }
        None => s += "linearized at rest about the initial placement\n",
    }
    if let Some(a) = m.off_equilibrium {
        s += &format!(
            "the placement is not an equilibrium under gravity and the loads (it starts with \
             accelerations up to {}): these are the modes about a state the scene leaves at \
             once; --equilibrium linearizes about its deformed equilibrium\n",
            significant(a, 3)
        );
    }
    if m.runs_planar {
        s += "the scene runs with the planar element (its motion stays in the x-y plane); \
              these are its 3D structure's modes, with the spatial element: the out-of-plane \
              ones included\n";
    }
    if m.locked.is_empty() {
        s += "joints locked: none\n";
    } else {
        s += &format!("joints locked: {}\n", m.locked.join(", "));
    }
    if !m.driven.is_empty() {
        s += &format!("joints held by a motion drive: {}\n", m.driven.join(", "));
    }
    s += &format!("rigid-body modes: {} (left out)\n", m.rigid_body_modes);
    if m.non_oscillating > 0 {
        s += &format!(
            "modes that do not oscillate (diverging or overdamped): {}\n",
            m.non_oscillating
        );
    }
    s += &report(&m.frequencies, count);
    if m.damped {
        for (k, d) in m.modes.iter().take(count).enumerate() {
            s += &format!(
                "damped mode {}: {} Hz, damping ratio {}\n",
                k + 1,
                significant(d.damped_frequency, 9),
                significant(d.damping_ratio, 4)
            );
        }
    }
    s
}

/// `mode <k>: <f> Hz` lines, k from 1, at most `count` of them.
pub fn report(frequencies: &[f64], count: usize) -> String {
    frequencies
        .iter()
        .take(count)
        .enumerate()
        .map(|(k, f)| format!("mode {}: {} Hz\n", k + 1, significant(*f, 9)))
        .collect()
}

/// `x` in fixed notation with `digits` significant digits (`%.9g` without exponent form).
pub fn significant(x: f64, digits: usize) -> String {
    if !x.is_finite() || x == 0.0 || digits == 0 {
        return format!("{x}");
    }
    // The exponent after rounding to `digits` digits (9.9999999996 → 1.00000000e1).
    let sci = format!("{:.*e}", digits - 1, x);
    let exp: i64 = sci
        .rsplit_once('e')
        .and_then(|(_, e)| e.parse().ok())
        .unwrap_or(0);
    let decimals = (digits as i64 - 1 - exp).max(0) as usize;
    format!("{x:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::{report, significant};

    #[test]
    fn nine_significant_digits() {
        assert_eq!(significant(2.0854751, 9), "2.08547510");
        assert_eq!(significant(118.84259, 9), "118.842590");
        assert_eq!(significant(9.9999999996, 9), "10.0000000");
        assert_eq!(significant(0.0123456789012, 9), "0.0123456789");
        assert_eq!(significant(1234567890123.0, 9), "1234567890123");
    }

    #[test]
    fn report_numbers_modes_from_one() {
        assert_eq!(
            report(&[1.5, 2.5, 3.5], 2),
            "mode 1: 1.50000000 Hz\nmode 2: 2.50000000 Hz\n"
        );
    }
}
