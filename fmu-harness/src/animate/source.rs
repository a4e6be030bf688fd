//! Where a run comes from: a CSV of `simulate` or `cosim`, an FMU run here, or a scene run
//! directly by the engine.

use super::{AnimateError, KnownScene};
use crate::HarnessError;
use fmu_beam::{Binding, VarType};
use fmu_beam::{Engine, Scene};
use std::io::Read;
use std::path::Path;

/// Recorded values by column (`time` first).
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    pub columns: Vec<String>,
    /// One vector per column, one value per recorded time.
    pub values: Vec<Vec<f64>>,
}

impl Recording {
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(self.values[k].clone())
    }

    /// CSV as `simulate` writes it: a header, then one line per time.
    pub fn csv(&self) -> String {
        let mut s = self.columns.join(",");
        s.push('\n');
        for r in 0..self.values.first().map_or(0, Vec::len) {
            let line: Vec<String> = self.values.iter().map(|c| format!("{:e}", c[r])).collect();
            s.push_str(&line.join(","));
            s.push('\n');
        }
        s
    }
}

/// Bytes of a run's CSV that `animate` reads: 1 GiB.
pub const MAX_CSV_BYTES: u64 = 1024 * 1024 * 1024;

/// A CSV with a header of names (quoted or not) and rows of numbers, such as `simulate`,
/// `cosim` and fmpy write; a regular file of at most [`MAX_CSV_BYTES`], and errors say where,
/// without quoting the file.
pub fn read_csv(path: &Path) -> Result<Recording, HarnessError> {
    let text = crate::input_file::read_text(path, "a run's CSV", MAX_CSV_BYTES)?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(AnimateError::Csv {
            path: path.into(),
            message: "empty file".into(),
        }
        .into());
    };
    let columns: Vec<String> = header
        .split(',')
        .map(|c| c.trim().trim_matches('"').to_string())
        .collect();
    if columns.first().map(String::as_str) != Some("time") {
        return Err(AnimateError::Csv {
            path: path.into(),
            message: "the first column must be `time`".into(),
        }
        .into());
    }
    let mut values = vec![Vec::new(); columns.len()];
    for (k, line) in lines {
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != columns.len() {
            return Err(AnimateError::CsvLine {
                path: path.into(),
                line: k + 1,
                message: format!("{} fields, the header has {}", fields.len(), columns.len()),
            }
            .into());
        }
        for (i, (c, f)) in values.iter_mut().zip(fields).enumerate() {
            let v = f.trim().parse::<f64>().map_err(|_| AnimateError::CsvLine {
                path: path.into(),
                line: k + 1,
                message: format!("field {} is not a number", i + 1),
            })?;
            c.push(v);
        }
    }
    Ok(Recording { columns, values })
}

/// The experiment a run of the FMU at `path` or the scene file at `path` would have (start,
/// stop, communication step), with `stop` and `step` as given, read before the run (for an
/// FMU, from its modelDescription.xml, defaults as `simulate` takes them); `None` for a CSV.
pub fn planned_experiment(
    path: &Path,
    stop: Option<f64>,
    step: Option<f64>,
) -> Result<Option<(f64, f64, f64)>, HarnessError> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if ext == "toml" {
        let ex = Scene::load(path)?.experiment;
        let (start, stop) = (ex.start_time, stop.unwrap_or(ex.stop_time));
        return Ok(Some((start, stop, step.unwrap_or(ex.step_size))));
    }
    if ext != "fmu" {
        return Ok(None);
    }
    let file = crate::input_file::open(path, "an FMU")?;
    let Ok(mut zip) = zip::ZipArchive::new(file) else {
        return Ok(None);
    };
    let Ok(entry) = zip.by_name("modelDescription.xml") else {
        return Ok(None);
    };
    let mut xml = String::new();
    let limit = crate::slave::MAX_EXTRACTED_BYTES;
    if entry.is_symlink() || entry.take(limit).read_to_string(&mut xml).is_err() {
        return Ok(None);
    }
    // an FMU the master would refuse is refused by the run, with the master's reasons
    let origin = path.join("modelDescription.xml");
    let Ok(md) = crate::slave::ModelDescription::parse(&xml, &origin) else {
        return Ok(None);
    };
    let de = md.default_experiment;
    let start = de.start_time.unwrap_or(0.0);
    let stop = stop.or(de.stop_time).unwrap_or(start + 1.0);
    let step = step.or(de.step_size).unwrap_or((stop - start) / 500.0);
    Ok(Some((start, stop, step)))
}

/// Runs an FMU with the project's master (its DefaultExperiment unless `stop`/`step` say
/// otherwise), recording every output; with the scene it carries, if it is one of ours. A run
/// of more than [`super::MAX_RECORDED_TIMES`] is refused before it starts.
pub fn run_fmu(
    path: &Path,
    stop: Option<f64>,
    step: Option<f64>,
) -> Result<(Recording, Option<Scene>), HarnessError> {
    if let Some((start, stop, step)) = planned_experiment(path, stop, step)? {
        super::check_recorded_times(start, stop, step)?;
    }
    let options = crate::simulate::Options {
        stop_time: stop,
        step,
        outputs: Vec::new(),
        on_warning: Some(|m| eprintln!("warning from the FMU: {m}")),
    };
    // A run the FMU ended early is drawn up to its last good time; the CSV and the page
    // show where it stops.
    let (r, ended) = crate::simulate::simulate(path, &options)?;
    if let Some(ended) = ended {
        eprintln!("warning: {ended}");
    }
    let mut columns = vec!["time".to_string()];
    columns.extend(r.columns);
    let values = (0..columns.len())
        .map(|k| r.rows.iter().map(|row| row[k]).collect())
        .collect();
    Ok((Recording { columns, values }, packaged_scene(path)?))
}

/// The scene packaged in one of our FMUs (`resources/scene.toml`), `None` for another FMU.
pub fn packaged_scene(path: &Path) -> Result<Option<Scene>, HarnessError> {
    let file = crate::input_file::open(path, "an FMU")?;
    let Ok(mut zip) = zip::ZipArchive::new(file) else {
        return Ok(None);
    };
    let Ok(mut entry) = zip.by_name("resources/scene.toml") else {
        return Ok(None);
    };
    let origin = format!("{}!resources/scene.toml", path.display());
    let refuse = |message: String| HarnessError::Input {
        origin: origin.clone(),
        message,
    };
    // The FMU is untrusted, as in `Slave::load`: no link, and no more than it may expand to.
    if entry.is_symlink() {
        return Err(refuse("a symbolic link: the master refuses it".into()));
    }
    let limit = crate::slave::MAX_EXTRACTED_BYTES;
    let mut text = String::new();
    (&mut entry)
        .take(limit + 1)
        .read_to_string(&mut text)
        .map_err(|e| HarnessError::io(path, "reading resources/scene.toml", e))?;
    if text.len() as u64 > limit {
        return Err(refuse(format!(
            "more than {limit} bytes: the master extracts at most that"
        )));
    }
    Ok(Some(Scene::from_toml_str(&text, &origin)?))
}

/// Runs a scene directly with the engine, from its experiment's start to `stop` (default
/// its stop time) with communication step `step` (default its step size), recording every
/// Real and Integer output at every communication point.
pub fn run_scene(
    scene: &Scene,
    origin: &str,
    stop: Option<f64>,
    step: Option<f64>,
) -> Result<Recording, HarnessError> {
    let engine_error = |source| HarnessError::Engine {
        origin: origin.to_string(),
        source,
    };
    let ex = &scene.experiment;
    let (start, stop, h) = (
        ex.start_time,
        stop.unwrap_or(ex.stop_time),
        step.unwrap_or(ex.step_size),
    );
    if !(stop > start && h > 0.0 && h.is_finite()) {
        return Err(crate::simulate::SimulateError::BadExperiment {
            start,
            stop,
            step: h,
        }
        .into());
    }
    super::check_recorded_times(start, stop, h)?;
    let mut e = Engine::new(scene.clone());
    e.set_start_time(start).map_err(engine_error)?;
    e.exit_initialization().map_err(engine_error)?;
    let outputs: Vec<(u32, VarType, String)> = e
        .variables()
        .variables
        .iter()
        .filter(|v| matches!(v.binding, Binding::Output(_)) && v.ty != VarType::Boolean)
        .filter(|v| v.causality == fmu_beam::Causality::Output)
        .map(|v| (v.vr, v.ty, v.name.clone()))
        .collect();
    let mut columns = vec!["time".to_string()];
    columns.extend(outputs.iter().map(|o| o.2.clone()));
    let mut values = vec![Vec::new(); columns.len()];
    let mut record = |e: &mut Engine, t: f64| -> Result<(), HarnessError> {
        values[0].push(t);
        for (k, (vr, ty, _)) in outputs.iter().enumerate() {
            let v = match ty {
                VarType::Integer => e.get_integer(*vr).map(f64::from),
                _ => e.get_real(*vr),
            }
            .map_err(engine_error)?;
            values[k + 1].push(v);
        }
        Ok(())
    };
    record(&mut e, start)?;
    let mut t = start;
    let mut n: u64 = 0;
    while t < stop - 1e-9 * h {
        let next = (start + (n + 1) as f64 * h).min(stop);
        e.do_step(t, next - t).map_err(engine_error)?;
        t = next;
        n += 1;
        record(&mut e, t)?;
    }
    Ok(Recording { columns, values })
}

/// A `--scene [PREFIX=]FILE` argument: a scene file or one of our FMUs.
pub fn known_scene(arg: &str) -> Result<KnownScene, HarnessError> {
    let (prefix, file) = match arg.split_once('=') {
        Some((p, f)) => (format!("{p}."), f),
        None => (String::new(), arg),
    };
    let path = Path::new(file);
    let scene = if path.extension().is_some_and(|e| e == "fmu") {
        packaged_scene(path)?.ok_or_else(|| AnimateError::Scene {
            origin: file.to_string(),
            message: "the FMU carries no resources/scene.toml (not made by fmu-harness)".into(),
        })?
    } else {
        Scene::load(path)?
    };
    Ok(KnownScene { prefix, scene })
}
