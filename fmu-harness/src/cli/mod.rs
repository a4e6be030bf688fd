//! The command line: `package`, `explain`, `modes`, `schema`, `reference`, `simulate`, `cosim`,
//! `animate` and `accuracy` (the benchmarks are `fmu-bench`'s, in bench/).

mod studies;

pub use studies::AccuracyArgs;
use studies::{accuracy_cmd, campbell_cmd, modes_cmd};

use crate::error::HarnessError;
use crate::{animate, cosim, package, reference, schema, simulate};
use clap::{Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(Debug, Parser)]
#[command(
    name = "fmu-harness",
    version,
    about = "Turns flexible-beam scene files into FMI 2.0 co-simulation FMUs"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Package a scene file as an FMI 2.0 (or, `--fmi-version 3`, 3.0) co-simulation FMU.
    Package {
        /// The scene file (TOML).
        scene: PathBuf,
        /// The FMU to write, e.g. build/fmus/<scene>.fmu.
        #[arg(short, long)]
        output: PathBuf,
        /// An engine library to embed, one per platform: `[PLATFORM=]PATH`, e.g.
        /// `--binary target/release/libfmu_beam.so --binary win64=fmu_beam.dll`; the platform
        /// (linux64, win64) is read from the file's header and must agree with the one named
        /// [default: target/release/libfmu_beam.so of this executable's target directory, else
        /// the one beside this executable; Linux only].
        #[arg(long)]
        binary: Vec<package::BinaryArg>,
        /// The FMI version of the FMU: 2 (the widest reach) or 3 (shape outputs as arrays,
        /// platform tuples; docs/fmi-versions.md).
        #[arg(long, default_value = "2")]
        fmi_version: crate::platform::FmiVersion,
    },
    /// Print the effects the scene's unit simulates, why, and their estimated share of the
    /// cost (the text the FMU carries in documentation/).
    Explain {
        /// The scene file (TOML).
        scene: PathBuf,
    },
    /// Print the scene's linearized natural frequencies in Hz, with its joints free or locked,
    /// at rest or about the steady state spinning at a hub speed (rigid-body modes counted and
    /// left out); or write its Campbell diagram (frequencies against hub speed) as CSV and PNG.
    Modes {
        /// The scene file (TOML).
        scene: PathBuf,
        /// How many modes to print (and to draw in a Campbell diagram).
        #[arg(long, default_value_t = 10)]
        count: usize,
        /// Hold this joint's coordinate where the scene starts it (repeatable).
        #[arg(long, value_name = "JOINT")]
        lock: Vec<String>,
        /// Hold every revolute, prismatic and spherical joint.
        #[arg(long)]
        lock_all: bool,
        /// Hub speed (rad/s): linearize about the steady state spinning at it, in the
        /// co-rotating frame (a hub about world z; no gravity or loads).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        speed: f64,
        /// The hub: a revolute joint to `world`, driven at the speed [default: the one such
        /// joint with a motion drive].
        #[arg(long, value_name = "JOINT")]
        hub: Option<String>,
        /// At rest: linearize about the static equilibrium under gravity and the loads at the
        /// start (a tensioned or sagging beam), not the undeformed placement.
        #[arg(long, conflicts_with_all = ["speed", "campbell"])]
        equilibrium: bool,
        /// Campbell diagram over hub speeds `START:STOP:COUNT` (rad/s), e.g. 0:10:21: writes
        /// PREFIX.csv and PREFIX.png.
        #[arg(long, value_name = "START:STOP:COUNT")]
        campbell: Option<String>,
        /// The Campbell diagram's files, without extension [default: <scene>_campbell].
        #[arg(short, long, value_name = "PREFIX")]
        output: Option<PathBuf>,
        /// Threads computing the Campbell diagram's speeds [default: all cores]; the CSV is
        /// the same as a serial run's, byte for byte.
        #[arg(long, value_name = "N", requires = "campbell", value_parser = clap::value_parser!(u64).range(1..=1024))]
        jobs: Option<u64>,
    },
    /// Write the JSON Schema of scene files (shipped as scenes/scene.schema.json; a scene whose
    /// first line is `#:schema ./scene.schema.json` is completed and checked by Taplo-based
    /// editors).
    Schema {
        /// The file to write [default: standard output].
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Write the scene reference (Markdown: every field of every table, with its type, unit,
    /// default, allowed values and the validator's rules), shipped as docs/scene-reference.md.
    Reference {
        /// The file to write [default: standard output].
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Run one FMI 2.0 co-simulation FMU (any, not only ours) with a fixed communication step
    /// and write the chosen variables at every communication point as CSV (time first).
    Simulate {
        /// The FMU.
        fmu: PathBuf,
        /// Stop time [default: the DefaultExperiment's].
        #[arg(long)]
        stop: Option<f64>,
        /// Communication step [default: the DefaultExperiment's stepSize].
        #[arg(long)]
        step: Option<f64>,
        /// Variables to record [default: every output].
        #[arg(long, value_delimiter = ',')]
        output: Vec<String>,
        /// The CSV file to write, whole or not at all [default: standard output, row by row:
        /// a run that fails keeps the rows already written and exits non-zero, the reason on
        /// standard error].
        #[arg(short = 'o', long = "csv")]
        csv: Option<PathBuf>,
    },
    /// Couple several FMI 2.0 co-simulation FMUs as a system file says (units, connections,
    /// fixed or variable communication step, Jacobi or Gauss-Seidel, input extrapolation,
    /// rollback); write the chosen outputs as CSV and print a summary.
    Cosim {
        /// The system file (TOML); FMU paths in it are relative to it.
        system: PathBuf,
        /// The CSV file to write, whole or not at all [default: standard output, row by row,
        /// summary on standard error; a run that fails keeps the rows already written and exits
        /// non-zero].
        #[arg(short = 'o', long = "csv")]
        csv: Option<PathBuf>,
    },
    /// Draw a run as it moved: a self-contained HTML page (time slider, play/pause, speed,
    /// deformation magnification, a 3D view turned with the mouse) and/or an animated GIF.
    Animate(AnimateArgs),
    /// Study how accurate the scene's outputs are and what accuracy costs: runs the scene at a
    /// ladder of fixed steps and of meshes, estimates each run's error from the runs
    /// themselves (Richardson's extrapolation with the observed order), and writes the
    /// work-precision table (CSV, Markdown on standard output), a chart (PNG), the cheapest
    /// settings that meet the target, a check of them against a finer run, and what limits
    /// the error (step, mesh or Newton's tolerance).
    Accuracy(AccuracyArgs),
}

/// Runs one command, writing its report to `out`.
pub fn run(cli: Cli, out: &mut dyn Write) -> Result<(), HarnessError> {
    run_with_engines(cli, &[], out)
}

/// [`run`], where `package` without `--binary` embeds `engines` (the Python package's own, one
/// per platform); with none, [`package::default_binary`].
pub fn run_with_engines(
    cli: Cli,
    engines: &[package::BinaryArg],
    out: &mut dyn Write,
) -> Result<(), HarnessError> {
    match cli.command {
        Command::Package {
            scene,
            output,
            binary,
            fmi_version,
        } => {
            let binary = if binary.is_empty() { engines } else { &binary };
            package_cmd(&scene, &output, binary, fmi_version, out)
        }
        Command::Simulate {
            fmu,
            stop,
            step,
            output,
            csv,
        } => simulate_cmd(&fmu, stop, step, output, csv.as_deref(), out),
        Command::Cosim { system, csv } => cosim_cmd(&system, csv.as_deref(), out),
        Command::Animate(args) => animate_cmd(args, out),
        Command::Explain { scene } => explain_cmd(&scene, out),
        Command::Schema { output } => {
            write_text(&schema::scene_schema_text(), output.as_deref(), out)
        }
        Command::Reference { output } => {
            write_text(&reference::scene_reference(), output.as_deref(), out)
        }
        Command::Modes {
            scene,
            count,
            lock,
            lock_all,
            speed,
            hub,
            equilibrium,
            campbell,
            output,
            jobs,
        } => {
            let options = fmu_beam::ModeOptions {
                lock,
                lock_all,
                speed,
                hub,
                equilibrium,
            };
            match campbell {
                Some(spec) => {
                    let jobs = jobs.map_or(0, |n| n as usize);
                    campbell_cmd(&scene, count, options, &spec, output, jobs, out)
                }
                None => modes_cmd(&scene, count, &options, out),
            }
        }
        Command::Accuracy(args) => accuracy_cmd(args, out),
    }
}

/// The error of writing the report to standard output (or the `out` given to [`run`]).
fn stdout_err(e: std::io::Error) -> HarnessError {
    HarnessError::io("<stdout>", "writing the report", e)
}

/// `package`: writes the FMU and one line naming it, its variables, GUID and engines.
fn package_cmd(
    scene: &Path,
    output: &Path,
    binary: &[package::BinaryArg],
    version: crate::platform::FmiVersion,
    out: &mut dyn Write,
) -> Result<(), HarnessError> {
    let p = package::package_as(scene, output, binary, version)?;
    let engines: Vec<String> = p
        .binaries
        .iter()
        .map(|(platform, path)| format!("{platform} {}", path.display()))
        .collect();
    writeln!(
        out,
        "{}: {} ({} variables, GUID {}, engines: {})",
        p.output.display(),
        p.model_identifier,
        p.variables,
        p.guid,
        engines.join(", ")
    )
    .map_err(stdout_err)
}

/// `simulate`: runs the FMU and streams its CSV, row by row, to `csv` or `out`. A file is
/// written as a temporary sibling (removed on an error or a signal) renamed at the end.
fn simulate_cmd(
    fmu: &Path,
    stop: Option<f64>,
    step: Option<f64>,
    outputs: Vec<String>,
    csv: Option<&Path>,
    out: &mut dyn Write,
) -> Result<(), HarnessError> {
    let options = simulate::Options {
        stop_time: stop,
        step,
        outputs,
        on_warning: Some(|m| eprintln!("warning from the FMU: {m}")),
    };
    let ended = match csv {
        Some(path) => write_csv_through_temporary(path, |sink| {
            simulate::simulate_into(fmu, &options, sink).map_err(HarnessError::from)
        })?,
        None => {
            let mut writer = simulate::CsvWriter::new(std::io::BufWriter::new(out));
            let ended = simulate::simulate_into(fmu, &options, &mut writer)?;
            writer.into_inner().flush().map_err(stdout_err)?;
            ended
        }
    };
    // The CSV is written, up to the last good time; the status tells a script it ended early.
    match ended {
        Some(ended) => Err(HarnessError::Ended(Box::new(ended))),
        None => Ok(()),
    }
}

/// A run a unit ended early is written, then reported with exit status 3.
fn ended(why: Option<String>) -> Result<(), HarnessError> {
    why.map_or(Ok(()), |e| Err(HarnessError::CosimEnded(e)))
}

/// `cosim`: runs the system; the CSV streams to `csv` (summary to `out`) or to `out` (summary
/// to standard error), a file through a temporary sibling as in `simulate`.
fn cosim_cmd(system: &Path, csv: Option<&Path>, out: &mut dyn Write) -> Result<(), HarnessError> {
    match csv {
        Some(path) => {
            let summary = write_csv_through_temporary(path, |sink| {
                cosim::cosim_into(system, sink).map_err(HarnessError::from)
            })?;
            writeln!(out, "{}wrote {}", summary.text(), path.display()).map_err(stdout_err)?;
            ended(summary.ended)
        }
        None => {
            let mut writer = simulate::CsvWriter::new(std::io::BufWriter::new(&mut *out));
            let summary = cosim::cosim_into(system, &mut writer)?;
            writer.into_inner().flush().map_err(stdout_err)?;
            eprint!("{}", summary.text());
            ended(summary.ended)
        }
    }
}

/// Runs `run` with a CSV writer on a new temporary sibling of `path` (registered, so that it
/// goes on an error or a signal), then moves it to `path`; a `path` that is not a regular file
/// or a new name is refused before the run ([`crate::output_file`]).
fn write_csv_through_temporary<T>(
    path: &Path,
    run: impl FnOnce(&mut dyn simulate::RowSink) -> Result<T, HarnessError>,
) -> Result<T, HarnessError> {
    crate::output_file::write_through_temporary(path, "writing the CSV", |file| {
        run(&mut simulate::CsvWriter::new(file))
    })
}

/// The page and the GIF that `animate` writes: `-o` by its extension (.html or .htm a page,
/// .gif a GIF), `--gif` a GIF (.gif); any other extension is refused before the run is made,
/// rather than writing one format under another's name.
fn animation_files(
    output: Option<PathBuf>,
    gif: Option<PathBuf>,
) -> Result<(Option<PathBuf>, Option<PathBuf>), HarnessError> {
    let extension = |p: &Path| {
        p.extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default()
    };
    let refuse = |name, path: &Path, rule| -> HarnessError {
        animate::AnimateError::BadOption {
            name,
            value: path.display().to_string(),
            rule,
        }
        .into()
    };
    if let Some(g) = &gif {
        if extension(g) != "gif" {
            return Err(refuse("--gif", g, "the GIF's name ends in .gif"));
        }
    }
    let (html, gif) =
        match output {
            None => (None, gif),
            Some(o) => match extension(&o).as_str() {
                "html" | "htm" => (Some(o), gif),
                "gif" if gif.is_none() => (None, Some(o)),
                "gif" => {
                    return Err(refuse(
                        "-o",
                        &o,
                        "a .gif, and --gif names a GIF too: give one",
                    ))
                }
                _ => return Err(refuse(
                    "-o",
                    &o,
                    "the format comes from the extension: .html (or .htm) for the page, .gif for \
                     the GIF; no other format is written",
                )),
            },
        };
    if html.is_none() && gif.is_none() {
        return Err(animate::AnimateError::BadOption {
            name: "--output/--gif",
            value: "none".into(),
            rule: "give the page (-o run.html), the GIF (-o run.gif or --gif run.gif) or both",
        }
        .into());
    }
    Ok((html, gif))
}

/// The options of `animate`.
#[derive(Debug, clap::Args)]
pub struct AnimateArgs {
    /// The run: a CSV of `simulate` or `cosim`, an FMU (run here with its
    /// DefaultExperiment), or a scene file (run directly by the engine).
    run: PathBuf,
    /// The file to write, its format from its extension: .html (or .htm) the page, .gif the
    /// GIF; any other is refused.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The animated GIF to write.
    #[arg(long)]
    gif: Option<PathBuf>,
    /// The scene whose bodies and joints a CSV holds: a scene file or one of our FMUs;
    /// `UNIT=FILE` for a cosim unit's outputs (`UNIT.<name>`). Repeatable.
    #[arg(long)]
    scene: Vec<String>,
    /// GIF frames per second of playback.
    #[arg(long, default_value_t = 25.0)]
    fps: f64,
    /// Simulated seconds per second of playback (0.25: four times slower than real time).
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// Deformation magnification [default: the largest deflection shown as about 10 % of
    /// its beam's length, at least 1].
    #[arg(long)]
    magnify: Option<f64>,
    /// GIF size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480")]
    size: String,
    /// Stop time of a run made here [default: the DefaultExperiment's].
    #[arg(long)]
    stop: Option<f64>,
    /// Communication step of a run made here [default: the DefaultExperiment's].
    #[arg(long)]
    step: Option<f64>,
    /// Write the run made here (FMU or scene) as CSV.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Write the GIF's geometry (frame times, magnification, world-to-pixel map) as JSON.
    #[arg(long)]
    metadata: Option<PathBuf>,
}

/// `animate`: gets the run (CSV read, FMU or scene run here), writes the page and/or GIF, and
/// reports what it drew.
fn animate_cmd(args: AnimateArgs, out: &mut dyn Write) -> Result<(), HarnessError> {
    let AnimateArgs {
        run,
        output,
        gif,
        scene,
        fps,
        speed,
        magnify,
        size,
        stop,
        step,
        csv,
        metadata,
    } = args;
    let (width, height) = parse_size(&size)?;
    let (output, gif) = animation_files(output, gif)?;
    // every file it would write is looked at before the run
    let outputs = [&output, &gif, &csv, &metadata];
    crate::output_file::check_all(outputs.iter().filter_map(|p| p.as_deref()))?;
    let options = animate::Options {
        html: output,
        gif,
        metadata,
        fps,
        speed,
        magnification: magnify,
        width,
        height,
    };
    // and the work it would do: the options, the recorded times and frames of a run made here
    animate::check_options(&options)?;
    let planned = animate::planned_experiment(&run, stop, step)?;
    // (an experiment that is no interval is refused by the run, saying so)
    if let Some((start, stop, step)) = planned.filter(|(a, b, h)| b > a && *h > 0.0) {
        animate::check_recorded_times(start, stop, step)?;
        animate::check_frames(stop - start, &options)?;
    }
    let started = std::time::Instant::now();
    let mut scenes: Vec<animate::KnownScene> = scene
        .iter()
        .map(|s| animate::known_scene(s))
        .collect::<Result<_, _>>()?;
    let (recording, title) = animate_recording(&run, stop, step, &mut scenes)?;
    let ran = started.elapsed().as_secs_f64();
    if let Some(path) = &csv {
        crate::output_file::write_atomically(path, recording.csv().as_bytes())?;
    }
    let motion = animate::Motion::from_run(&recording, &scenes, &title)?;
    let (m, written) = animate::write(&motion, &options)?;
    writeln!(
        out,
        "{title}: {} recorded times from {} to {} s ({:.2} s to get them); {} beam(s), \
         {} bodies, {} joints; deformation x {m} (largest deflection {:.3} % of its \
         beam's length)",
        motion.times.len(),
        motion.times[0],
        motion.times[motion.times.len() - 1],
        ran,
        motion.beams.len(),
        motion.bodies.len(),
        motion.joints.len(),
        100.0 * motion.largest_deflection_ratio()
    )
    .map_err(stdout_err)?;
    if scenes.is_empty() {
        writeln!(
            out,
            "(beams only: give --scene FILE to draw the bodies and joints of a CSV)"
        )
        .map_err(stdout_err)?;
    }
    for w in written {
        writeln!(
            out,
            "wrote {} ({} frames, {:.1} kB, {:.2} s)",
            w.path.display(),
            w.frames,
            w.bytes as f64 / 1024.0,
            w.seconds
        )
        .map_err(stdout_err)?;
    }
    Ok(())
}

/// The run `animate` draws and its title: an FMU or a scene is run here (its scene then added
/// to `scenes` when none was given), anything else read as a CSV.
fn animate_recording(
    run: &Path,
    stop: Option<f64>,
    step: Option<f64>,
    scenes: &mut Vec<animate::KnownScene>,
) -> Result<(animate::Recording, String), HarnessError> {
    let ext = run.extension().and_then(|e| e.to_str()).unwrap_or("");
    let stem = run
        .file_stem()
        .map_or("run".into(), |s| s.to_string_lossy().to_string());
    Ok(match ext {
        "fmu" => {
            let (rec, packaged) = animate::run_fmu(run, stop, step)?;
            if let (Some(s), true) = (packaged, scenes.is_empty()) {
                scenes.push(animate::KnownScene {
                    prefix: String::new(),
                    scene: s,
                });
            }
            (rec, stem)
        }
        "toml" => {
            let s = fmu_beam::Scene::load(run)?;
            let rec = animate::run_scene(&s, &run.display().to_string(), stop, step)?;
            let name = s.name.clone();
            if scenes.is_empty() {
                scenes.push(animate::KnownScene {
                    prefix: String::new(),
                    scene: s,
                });
            }
            (rec, name)
        }
        _ => (animate::read_csv(run)?, stem),
    })
}

/// `explain`: the accuracy the scene was tuned for, its effects, why, and their share of the
/// cost.
fn explain_cmd(scene: &Path, out: &mut dyn Write) -> Result<(), HarnessError> {
    let text = crate::package::explain(&fmu_beam::Scene::load(scene)?)?;
    out.write_all(text.as_bytes()).map_err(stdout_err)
}

/// `WIDTHxHEIGHT` in pixels.
fn parse_size(s: &str) -> Result<(u32, u32), HarnessError> {
    let bad = || animate::AnimateError::BadOption {
        name: "--size",
        value: s.to_string(),
        rule: "WIDTHxHEIGHT in pixels, e.g. 640x480",
    };
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    Ok((
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

/// Writes generated text to a file, or to `out`.
fn write_text(text: &str, path: Option<&Path>, out: &mut dyn Write) -> Result<(), HarnessError> {
    match path {
        Some(p) => crate::output_file::write_atomically(p, text.as_bytes()),
        None => out.write_all(text.as_bytes()).map_err(stdout_err),
    }
}
