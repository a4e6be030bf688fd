//! The command line: `package`, `explain`, `modes`, `work-precision`, `linear-solvers`,
//! `simulate` and `cosim`.

use crate::error::HarnessError;
use crate::{cosim, linear_solvers, modes, package, simulate, work_precision};
use clap::{Parser, Subcommand};
use std::io::Write;
use std::path::PathBuf;

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
    /// Package a scene file as an FMI 2.0 co-simulation FMU.
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
    },
    /// Print the effects the scene's unit simulates, why, and their estimated share of the
    /// cost (the text the FMU carries in documentation/).
    Explain {
        /// The scene file (TOML).
        scene: PathBuf,
    },
    /// Print the scene's linearized natural frequencies in Hz (rigid-body modes left out).
    Modes {
        /// The scene file (TOML).
        scene: PathBuf,
        /// How many modes to print.
        #[arg(long, default_value_t = 10)]
        count: usize,
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
        /// The CSV file to write [default: standard output].
        #[arg(short = 'o', long = "csv")]
        csv: Option<PathBuf>,
    },
    /// Couple several FMI 2.0 co-simulation FMUs as a system file says (units, connections,
    /// fixed or variable communication step, Jacobi or Gauss-Seidel, input extrapolation,
    /// rollback); write the chosen outputs as CSV and print a summary.
    Cosim {
        /// The system file (TOML); FMU paths in it are relative to it.
        system: PathBuf,
        /// The CSV file to write [default: standard output, summary on standard error].
        #[arg(short = 'o', long = "csv")]
        csv: Option<PathBuf>,
    },
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
        /// and integrator mode are skipped.
        #[arg(long, default_value_t = 4.0)]
        budget: f64,
        /// Only these cases (c2, c3_elastic, c3_rigid, c4_omega10, c4_omega4).
        #[arg(long, value_delimiter = ',')]
        cases: Vec<String>,
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
}

/// Runs one command, writing its report to `out`.
pub fn run(cli: Cli, out: &mut dyn Write) -> Result<(), HarnessError> {
    let stdout_err = |e| HarnessError::io("<stdout>", "writing the report", e);
    match cli.command {
        Command::Package {
            scene,
            output,
            binary,
        } => {
            let p = package::package(&scene, &output, &binary)?;
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
            .map_err(stdout_err)?;
        }
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
        } => {
            use work_precision::peer;
            let chosen: Vec<_> = peer::cases()
                .into_iter()
                .filter(|c| cases.is_empty() || cases.iter().any(|n| n == c.name))
                .collect();
            let started = std::time::Instant::now();
            let mut progress = |line: &str| eprintln!("{line}");
            let ours = peer::study(
                &scenes,
                &references,
                &chosen,
                repeats,
                budget,
                &mut progress,
            )?;
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
            let header = format!(
                "{} timed runs per point; our sweep took {:.0} s; the peer's points from {}.",
                repeats,
                started.elapsed().as_secs_f64(),
                peer_points.display()
            );
            let text = peer::report(&chosen, &ours, &theirs, &header);
            for path in peer::write(&output, &ours, &text)? {
                writeln!(out, "wrote {}", path.display()).map_err(stdout_err)?;
            }
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
                "Generated by `make bench` (`fmu-harness linear-solvers --rounds {rounds}`) in \
                 {:.0} s wall time. Reproduce: `cargo run --release -p fmu-harness -- \
                 linear-solvers --scenes scenes --output build/bench`.\n",
                started.elapsed().as_secs_f64()
            );
            for path in linear_solvers::write(&output, &rows, rounds, &header)? {
                writeln!(out, "wrote {}", path.display()).map_err(stdout_err)?;
            }
        }
        Command::Simulate {
            fmu,
            stop,
            step,
            output,
            csv,
        } => {
            let options = simulate::Options {
                stop_time: stop,
                step,
                outputs: output,
            };
            let text = simulate::simulate(&fmu, &options)?.csv();
            match csv {
                Some(path) => std::fs::write(&path, text)
                    .map_err(|e| HarnessError::io(&path, "writing the CSV", e))?,
                None => out.write_all(text.as_bytes()).map_err(stdout_err)?,
            }
        }
        Command::Cosim { system, csv } => {
            let (results, summary) = cosim::cosim(&system)?;
            match csv {
                Some(path) => {
                    std::fs::write(&path, results.csv())
                        .map_err(|e| HarnessError::io(&path, "writing the CSV", e))?;
                    writeln!(out, "{}wrote {}", summary.text(), path.display())
                        .map_err(stdout_err)?;
                }
                None => {
                    out.write_all(results.csv().as_bytes())
                        .map_err(stdout_err)?;
                    eprint!("{}", summary.text());
                }
            }
        }
        Command::Explain { scene } => {
            let scene = fmu_beam::Scene::load(&scene)?;
            let text = fmu_beam::effects::resolve(&scene).explain(&scene);
            out.write_all(text.as_bytes()).map_err(stdout_err)?;
        }
        Command::Modes { scene, count } => {
            let f = modes::elastic_frequencies(&scene)?;
            out.write_all(modes::report(&f, count).as_bytes())
                .map_err(stdout_err)?;
        }
    }
    Ok(())
}
