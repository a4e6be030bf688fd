//! The command line: `package` and `modes`.

use crate::error::HarnessError;
use crate::{modes, package};
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
        /// The engine library to embed [default: target/release/libfmu_beam.so of this
        /// executable's target directory, else the one beside this executable].
        #[arg(long)]
        binary: Option<PathBuf>,
    },
    /// Print the scene's linearized natural frequencies in Hz (rigid-body modes left out).
    Modes {
        /// The scene file (TOML).
        scene: PathBuf,
        /// How many modes to print.
        #[arg(long, default_value_t = 10)]
        count: usize,
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
            let p = package::package(&scene, &output, binary.as_deref())?;
            writeln!(
                out,
                "{}: {} ({} variables, GUID {}, engine {})",
                p.output.display(),
                p.model_identifier,
                p.variables,
                p.guid,
                p.binary.display()
            )
            .map_err(stdout_err)?;
        }
        Command::Modes { scene, count } => {
            let f = modes::elastic_frequencies(&scene)?;
            out.write_all(modes::report(&f, count).as_bytes())
                .map_err(stdout_err)?;
        }
    }
    Ok(())
}
