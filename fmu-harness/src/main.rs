use clap::Parser;
use fmu_harness::cli::{run, Cli};

fn main() {
    let cli = Cli::parse();
    let stdout = std::io::stdout();
    if let Err(e) = run(cli, &mut stdout.lock()) {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}
