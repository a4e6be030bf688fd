//! fmu-bench: the benchmarks of the engine, beside the product (`make bench`, `make
//! bench-peer`): `work-precision` (error against CPU time over formulations, integrator
//! settings and effects), `peer` (C2–C4 against the exact references and against Exudyn),
//! `peer-run` (one of its settings alone, for `bench/peer/interleaved.py` and callgrind),
//! `choice` (the accuracy study's chosen scene against the cheapest of our peer points) and
//! `linear-solvers` (dense against sparse LU of the iteration matrix), `scaling` (how set-up
//! and step cost grow with the model).

mod error;
mod linear_solvers;
mod scaling;
mod work_precision;

use clap::{Parser, Subcommand};
use error::BenchError;
use std::io::Write;
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "fmu-bench",
    version,
    about = "Benchmarks of the fmu-beam engine: work-precision, the peer comparison, linear solvers"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Work-precision study of the validation cases C1–C4: every formulation (elements,
    /// substructures, rigid parts, modal truncation, stiffening) at every integrator setting
    /// against one reference per case, then each effect switched off in turn; writes
    /// points.csv and REPORT.md.
    WorkPrecision {
        /// Directory of the scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Output directory.
        #[arg(short, long, default_value = "build/bench")]
        output: PathBuf,
        /// Timed runs per point (median, min and max are reported).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// CPU seconds of one run above which the tighter settings of the same formulation
        /// and integrator mode are skipped.
        #[arg(long, default_value_t = 2.5)]
        budget: f64,
        /// Only these cases: C1, C2, C3, C4 (planar), C5, C6, F3 (3D: the roll-up, the
        /// pendulum, the fast variants), or 3D for all three.
        #[arg(long, value_delimiter = ',')]
        cases: Vec<String>,
    },
    /// C2–C4 against the exact references of bench/reference and against the peer (Exudyn,
    /// whose points `bench/peer/sweep.py` writes): the CPU time ratio of the cheapest run of
    /// each tool that meets 1e-2 … 1e-5; writes ours_points.csv and PEER.md.
    Peer {
        /// Directory of the scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Directory of the reference CSVs.
        #[arg(long, default_value = "bench/reference")]
        references: PathBuf,
        /// The peer's points (without it, or if it does not exist, only ours are written).
        #[arg(long, default_value = "build/bench/peer_points.csv")]
        peer_points: PathBuf,
        /// Output directory.
        #[arg(short, long, default_value = "build/bench")]
        output: PathBuf,
        /// Timed runs per point (median, min and max are reported).
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// CPU seconds of one run above which the tighter settings of the same formulation
        /// and integrator mode are skipped (a case may allow more: C2, 20 s, for the steps
        /// its tip deflection needs).
        #[arg(long, default_value_t = 4.0)]
        budget: f64,
        /// Only these cases (c2, c3_elastic, c3_rigid, c4_omega10, c4_omega4).
        #[arg(long, value_delimiter = ',')]
        cases: Vec<String>,
        /// Our points from an earlier run (its ours_points.csv) instead of a new sweep: the
        /// report again, in seconds.
        #[arg(long)]
        ours_points: Option<PathBuf>,
    },
    /// One of our peer settings alone: a case, a formulation and a setting as
    /// ours_points.csv names them; prints one JSON line: CPU seconds (thread) of the first run
    /// and of each sample, errors against the reference, steps, Newton iterations, iteration
    /// matrices and unknowns (`bench/peer/interleaved.py`; under callgrind with --samples 0).
    PeerRun {
        /// Directory of the scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Directory of the reference CSVs.
        #[arg(long, default_value = "bench/reference")]
        references: PathBuf,
        /// c2, c3_elastic, c3_rigid, c4_omega10 or c4_omega4.
        #[arg(long)]
        case: String,
        /// A formulation of the case, e.g. "10 x 2 substructures".
        #[arg(long)]
        formulation: String,
        /// A setting, e.g. "fixed step 1.0e-3 s, tolerance 1e-8" or "tolerance 1e-6".
        #[arg(long)]
        setting: String,
        /// End time (s) instead of the case's (a multiple of its communication step).
        #[arg(long)]
        stop: Option<f64>,
        /// Timed samples after the first run (0: the first run only).
        #[arg(long, default_value_t = 1)]
        samples: usize,
    },
    /// The accuracy study's choice against the peer bench's cheapest (issue 34 item 2): the
    /// scene `fmu-harness accuracy` chose for a target and the cheapest of our peer points
    /// meeting it on the same output, timed in one process round by round; prints a table row.
    Choice {
        /// Directory of the scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Directory of the reference CSVs.
        #[arg(long, default_value = "bench/reference")]
        references: PathBuf,
        /// Our points of the peer sweep.
        #[arg(long, default_value = "build/bench/ours_points.csv")]
        ours_points: PathBuf,
        /// The peer case (c2, c3_elastic, c3_rigid, c4_omega10, c4_omega4).
        #[arg(long)]
        case: String,
        /// The reference column (tip_deflection, slider_position, ...).
        #[arg(long)]
        output: String,
        /// The error target.
        #[arg(long)]
        target: f64,
        /// The study's chosen scene (`chosen.toml` in its folder).
        #[arg(long)]
        chosen: PathBuf,
        /// Timed rounds (median, least and largest are reported).
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Print the table's header first.
        #[arg(long)]
        header: bool,
    },
    /// The exhaustive sweep behind the accuracy study's choice (issue 46 item 1): C2–C4 over
    /// every mesh the study reaches and the quarter octaves of its steps, against the exact
    /// references, counted and timed; the cheapest setting meeting each target with the
    /// study's safety factor against the study's choice (`build/accuracy/<case>-<target>/`),
    /// and the fit of the counted costs to CPU time; writes exhaustive.csv and EXHAUSTIVE.md.
    Exhaustive {
        /// Directory of the scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Directory of the reference CSVs.
        #[arg(long, default_value = "bench/reference")]
        references: PathBuf,
        /// Output directory.
        #[arg(short, long, default_value = "build/bench")]
        output: PathBuf,
        /// Only these cases (c2, c3_elastic, c3_rigid, c4_omega10, c4_omega4).
        #[arg(long, value_delimiter = ',')]
        cases: Vec<String>,
        /// CPU seconds of a run above which a mesh's finer steps are left out.
        #[arg(long, default_value_t = 30.0)]
        max_cpu: f64,
        /// The points of an earlier sweep (its exhaustive.csv) instead of a new one.
        #[arg(long)]
        points: Option<PathBuf>,
        /// The studies' folders (`make bench-accuracy`'s build/accuracy).
        #[arg(long, default_value = "build/accuracy")]
        studies: PathBuf,
        /// Timed rounds of each choice against the sweep's cheapest.
        #[arg(long, default_value_t = 5)]
        rounds: usize,
    },
    /// Dense against sparse LU of the iteration matrix: C2's pendulum and C4's spin-up with
    /// k = 5…80 substructures and C1's beam with e elements, at fixed steps; CPU time per step,
    /// per factorization and per solve; writes LINEAR.md and linear_solvers.csv.
    LinearSolvers {
        /// Directory of the scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Output directory.
        #[arg(short, long, default_value = "build/bench")]
        output: PathBuf,
        /// Timed rounds (median, min and max are reported).
        #[arg(long, default_value_t = 5)]
        rounds: usize,
    },
    /// How the cost grows with the model (issue 46 item 3): C2's pendulum as n substructures
    /// and as one frame of n elements, n = 4 … 128; set-up (instantiate to ready to step) and
    /// CPU time per step at a fixed step with its counters, and the fitted exponents; writes
    /// SCALING.md.
    Scaling {
        /// Directory of the scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Output directory.
        #[arg(short, long, default_value = "build/bench")]
        output: PathBuf,
        /// Timed rounds (the median is reported).
        #[arg(long, default_value_t = 5)]
        rounds: usize,
    },
}

fn main() {
    let cli = Cli::parse();
    let stdout = std::io::stdout();
    if let Err(e) = run(cli, &mut stdout.lock()) {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}

/// Runs one command, writing its report to `out`.
fn run(cli: Cli, out: &mut dyn Write) -> Result<(), BenchError> {
    let stdout_err = |e| BenchError::io("<stdout>", "writing the report", e);
    match cli.command {
        Command::WorkPrecision {
            scenes,
            output,
            repeats,
            budget,
            cases,
        } => {
            let wanted = |name: &str| {
                cases.is_empty()
                    || cases.iter().any(|n| {
                        n == name || (n == "3D" && work_precision::spatial::NAMES.contains(&name))
                    })
            };
            let chosen: Vec<_> = work_precision::cases::cases()
                .into_iter()
                .filter(|c| wanted(c.name))
                .collect();
            let spatial: Vec<&str> = work_precision::spatial::NAMES
                .into_iter()
                .filter(|n| wanted(n))
                .collect();
            let options = work_precision::Options { repeats, budget };
            let started = std::time::Instant::now();
            let mut progress = |line: &str| eprintln!("{line}");
            let results = work_precision::study(&scenes, &chosen, &options, &mut progress)?;
            let spatial = if spatial.is_empty() {
                None
            } else {
                Some(work_precision::spatial::study(
                    &scenes,
                    &spatial,
                    &options,
                    &mut progress,
                )?)
            };
            let header = format!(
                "{}\n\n{}",
                work_precision::header(&options, started.elapsed().as_secs_f64()),
                work_precision::overhead::table(&scenes, 5)?
            );
            for path in work_precision::report::write(&output, &results, spatial.as_ref(), &header)?
            {
                writeln!(out, "wrote {}", path.display()).map_err(stdout_err)?;
            }
        }
        Command::Peer {
            scenes,
            references,
            peer_points,
            output,
            repeats,
            budget,
            cases,
            ours_points,
        } => {
            use work_precision::peer;
            let chosen: Vec<_> = peer::cases()
                .into_iter()
                .filter(|c| cases.is_empty() || cases.iter().any(|n| n == c.name))
                .collect();
            let started = std::time::Instant::now();
            let mut progress = |line: &str| eprintln!("{line}");
            let ours = match &ours_points {
                Some(path) => peer::read_peer(path)?
                    .into_iter()
                    .filter(|p| chosen.iter().any(|c| c.name == p.case))
                    .collect(),
                None => peer::study(
                    &scenes,
                    &references,
                    &chosen,
                    repeats,
                    budget,
                    &mut progress,
                )?,
            };
            let theirs = if peer_points.is_file() {
                peer::read_peer(&peer_points)?
            } else {
                writeln!(
                    out,
                    "{} does not exist (run bench/peer/sweep.py): our points only",
                    peer_points.display()
                )
                .map_err(stdout_err)?;
                Vec::new()
            };
            let header = match &ours_points {
                Some(path) => format!(
                    "Our points from {}; the peer's points from {}.",
                    path.display(),
                    peer_points.display()
                ),
                None => format!(
                    "{} timed runs per point; our sweep took {:.0} s; the peer's points from {}.",
                    repeats,
                    started.elapsed().as_secs_f64(),
                    peer_points.display()
                ),
            };
            let text = peer::report(&chosen, &ours, &theirs, &header);
            for path in peer::write(&output, &ours, &text)? {
                writeln!(out, "wrote {}", path.display()).map_err(stdout_err)?;
            }
            out.write_all(text.as_bytes()).map_err(stdout_err)?;
        }
        Command::PeerRun {
            scenes,
            references,
            case,
            formulation,
            setting,
            stop,
            samples,
        } => {
            let line = work_precision::peer_run::run(&work_precision::peer_run::Request {
                scenes: &scenes,
                references: &references,
                case: &case,
                formulation: &formulation,
                setting: &setting,
                stop,
                samples,
            })?;
            writeln!(out, "{line}").map_err(stdout_err)?;
        }
        Command::Choice {
            scenes,
            references,
            ours_points,
            case,
            output,
            target,
            chosen,
            repeats,
            header,
        } => {
            use work_precision::{choice, peer};
            let c = peer::cases()
                .into_iter()
                .find(|c| c.name == case)
                .ok_or_else(|| BenchError::Input {
                    origin: "--case".into(),
                    message: format!("no peer case {case}"),
                })?;
            let ours = peer::read_peer(&ours_points)?;
            let row = choice::compare(
                &scenes,
                &references,
                &c,
                &output,
                target,
                &chosen,
                &ours,
                repeats,
            )?
            .row();
            if header {
                writeln!(out, "{}", choice::HEADER).map_err(stdout_err)?;
            }
            writeln!(out, "{row}").map_err(stdout_err)?;
        }
        Command::Exhaustive {
            scenes,
            references,
            output,
            cases,
            max_cpu,
            points,
            studies,
            rounds,
        } => {
            use work_precision::exhaustive as ex;
            let started = std::time::Instant::now();
            let mut progress = |line: &str| eprintln!("{line}");
            std::fs::create_dir_all(&output)
                .map_err(|e| BenchError::io(&output, "creating the folder", e))?;
            let all = match &points {
                Some(path) => ex::read(path)?,
                None => {
                    let mut all = Vec::new();
                    for case in ex::CASES
                        .iter()
                        .filter(|c| cases.is_empty() || cases.iter().any(|n| n == c.name))
                    {
                        all.extend(ex::sweep(
                            &scenes,
                            &references,
                            case,
                            max_cpu,
                            &mut progress,
                        )?);
                        let csv = output.join("exhaustive.csv");
                        std::fs::write(&csv, ex::csv(&all))
                            .map_err(|e| BenchError::io(&csv, "writing the points", e))?;
                    }
                    all
                }
            };
            let swept = started.elapsed().as_secs_f64();
            let studies = studies.is_dir().then_some(studies.as_path());
            let table = ex::report(&scenes, &all, studies, rounds, &mut progress);
            let text = format!(
                "# The accuracy study against an exhaustive sweep\n\n{} runs{}.\n\n{table}\n{}",
                all.len(),
                if points.is_some() {
                    String::new()
                } else {
                    format!(", swept in {swept:.0} s wall")
                },
                ex::fit_table(&all)
            );
            let md = output.join("EXHAUSTIVE.md");
            std::fs::write(&md, &text).map_err(|e| BenchError::io(&md, "writing the report", e))?;
            out.write_all(text.as_bytes()).map_err(stdout_err)?;
        }
        Command::LinearSolvers {
            scenes,
            output,
            rounds,
        } => {
            let started = std::time::Instant::now();
            let rows =
                linear_solvers::study(&scenes, rounds, &mut |line: &str| eprintln!("{line}"))?;
            let header = format!(
                "Generated by `make bench` (`fmu-bench linear-solvers --rounds {rounds}`) in \
                 {:.0} s wall time. Reproduce: `cargo run --release -p fmu-bench -- \
                 linear-solvers --scenes scenes --output build/bench`.\n",
                started.elapsed().as_secs_f64()
            );
            for path in linear_solvers::write(&output, &rows, rounds, &header)? {
                writeln!(out, "wrote {}", path.display()).map_err(stdout_err)?;
            }
        }
        Command::Scaling {
            scenes,
            output,
            rounds,
        } => {
            let started = std::time::Instant::now();
            let rows = scaling::study(&scenes, rounds, &mut |line: &str| eprintln!("{line}"))?;
            let header = format!(
                "Generated by `make bench-scaling` (`fmu-bench scaling --rounds {rounds}`) in \
                 {:.0} s wall time.",
                started.elapsed().as_secs_f64()
            );
            let text = scaling::markdown(&rows, rounds, &header);
            std::fs::create_dir_all(&output)
                .map_err(|e| BenchError::io(&output, "creating the folder", e))?;
            let path = output.join("SCALING.md");
            std::fs::write(&path, &text)
                .map_err(|e| BenchError::io(&path, "writing the report", e))?;
            out.write_all(text.as_bytes()).map_err(stdout_err)?;
            writeln!(out, "wrote {}", path.display()).map_err(stdout_err)?;
        }
    }
    Ok(())
}
