use clap::Parser;
use fmu_harness::cli::{run, Cli};

fn main() {
    let cli = Cli::parse();
    // Extraction folders and half-written files go on SIGINT, SIGTERM and SIGHUP too.
    if let Err(e) = fmu_harness::scratch::remove_on_signals() {
        eprintln!("warning: temporary files will stay behind if interrupted: {e}");
    }
    let stdout = std::io::stdout();
    if let Err(e) = run(cli, &mut stdout.lock()) {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}
