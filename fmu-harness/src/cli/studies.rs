//! The study commands of the command line: `modes` (with `--campbell`) and `accuracy`, and the
//! latter's options.

use super::stdout_err;
use crate::error::HarnessError;
use crate::{accuracy, modes};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The options of `accuracy`.
#[derive(Debug, clap::Args)]
pub struct AccuracyArgs {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// An output to study (repeat for several; the error is the largest of theirs).
    #[arg(long = "output", required = true)]
    pub outputs: Vec<String>,
    /// The error to meet: max over the grid of |y − y*| / max |y*|.
    #[arg(long, allow_hyphen_values = true)]
    pub target: f64,
    /// Stop time [default: the scene's experiment].
    #[arg(long, allow_hyphen_values = true)]
    pub stop: Option<f64>,
    /// The grid the outputs are compared on [default: the experiment's step_size].
    #[arg(long, allow_hyphen_values = true)]
    pub comm: Option<f64>,
    /// The time ladder's coarsest fixed step [default: the larger of the communication step
    /// and the scene's max_step].
    #[arg(long, allow_hyphen_values = true)]
    pub step: Option<f64>,
    /// Newton's tolerance at the coarsest step, divided by 4 at each halving [default: the
    /// smaller of the scene's tolerance and target / 10].
    #[arg(long, allow_hyphen_values = true)]
    pub newton: Option<f64>,
    /// Steps in the time ladder (each half the one before); more where none is within half
    /// the target, or where the observed order is implausible at the target's scale.
    #[arg(long, default_value_t = 5)]
    pub levels: usize,
    /// Meshes in the mesh ladder: the scene's, then each flexible beam's elements (or
    /// substructures) doubled; more as for --levels. The halved mesh (rounded up) also runs.
    #[arg(long, default_value_t = 3)]
    pub mesh_levels: usize,
    /// One study only: not run again at the chosen mesh (or the halved one) where that mesh's
    /// own time ladder may allow a cheaper setting.
    #[arg(long)]
    pub no_recentre: bool,
    /// The study's budget: runs (both studies, where it is re-centred).
    #[arg(long, default_value_t = 60)]
    pub max_runs: usize,
    /// The study's budget: counted work (steps, Newton iterations and iteration matrices
    /// weighed by the system's size; about a CPU second a unit where fitted). A run predicted
    /// to pass it is left out and said; the same on any machine and under any load.
    #[arg(long, default_value_t = accuracy::DEFAULT_MAX_WORK, allow_hyphen_values = true)]
    pub max_work: f64,
    /// A safety stop in wall seconds: where it fires, the study stops and its report says
    /// INCOMPLETE (its choice is then that of the runs before the stop).
    #[arg(long, default_value_t = accuracy::DEFAULT_MAX_SECONDS, allow_hyphen_values = true)]
    pub max_seconds: f64,
    /// Runs run at once [default: every core]. Runs the study will probably ask for next are
    /// run ahead; the choice and the table are those of --jobs 1, but for the seconds.
    #[arg(long)]
    pub jobs: Option<usize>,
    /// A reference CSV (time first, on the study's grid; e.g. bench/reference/c4_omega10.csv):
    /// each run's true error is reported beside its estimate.
    #[arg(long, requires = "columns")]
    pub reference: Option<PathBuf>,
    /// The reference's column for each --output, in the same order.
    #[arg(long = "column", requires = "reference")]
    pub columns: Vec<String>,
    /// The folder for accuracy.csv and accuracy.png [default: build/accuracy/<scene name>].
    #[arg(long)]
    pub dir: Option<PathBuf>,
}

/// `modes`: what was linearized, then the first `count` natural frequencies.
pub(super) fn modes_cmd(
    scene_path: &Path,
    count: usize,
    options: &fmu_beam::ModeOptions,
    out: &mut dyn Write,
) -> Result<(), HarnessError> {
    let scene = fmu_beam::Scene::load(scene_path)?;
    let m = modes::modes_of(&scene, &scene_path.display().to_string(), options)?;
    out.write_all(modes::full_report(&m, count).as_bytes())
        .map_err(stdout_err)
}

/// `accuracy`: runs the study, writes its CSV and PNG, prints the Markdown report.
pub(super) fn accuracy_cmd(args: AccuracyArgs, out: &mut dyn Write) -> Result<(), HarnessError> {
    let mut o = accuracy::Options::new(args.outputs, args.target);
    o.stop = args.stop;
    o.comm = args.comm;
    o.step = args.step;
    o.newton = args.newton;
    o.levels = args.levels;
    o.mesh_levels = args.mesh_levels;
    o.max_runs = args.max_runs;
    o.max_work = args.max_work;
    o.max_seconds = args.max_seconds;
    o.jobs = args.jobs;
    o.reference = args.reference.map(|p| (p, args.columns));
    o.progress = true;
    o.recentre = !args.no_recentre;
    o.check()?;
    let scene = fmu_beam::Scene::load(&args.scene)?;
    // the files it writes are looked at before the study
    let dir = args
        .dir
        .unwrap_or_else(|| Path::new("build/accuracy").join(&scene.name));
    let [csv, json, png, chosen] =
        ["accuracy.csv", "study.json", "accuracy.png", "chosen.toml"].map(|f| dir.join(f));
    crate::output_file::check_all([csv.as_path(), &json, &png, &chosen])?;
    let study = accuracy::study(&scene, &o)?;
    crate::output_file::write_atomically(&csv, accuracy::report::csv(&study).as_bytes())?;
    crate::output_file::write_atomically(&json, accuracy::report::json(&study).as_bytes())?;
    crate::output_file::write_atomically(&png, &accuracy::plot::png(&study))?;
    let mut wrote = format!("{} and {}", csv.display(), png.display());
    if let Some(c) = &study.choice {
        crate::output_file::write_atomically(&chosen, c.scene_toml.as_bytes())?;
        wrote = format!(
            "{}, {wrote} (the scene at the chosen setting)",
            chosen.display()
        );
    }
    write!(
        out,
        "{}\nWrote {wrote}.\n",
        accuracy::report::markdown(&study)
    )
    .map_err(stdout_err)
}

/// `modes --campbell`: the first `count` frequencies at each speed, as CSV and PNG, the speeds
/// computed on `jobs` threads (0: all cores).
pub(super) fn campbell_cmd(
    scene_path: &Path,
    count: usize,
    options: fmu_beam::ModeOptions,
    spec: &str,
    output: Option<PathBuf>,
    jobs: usize,
    out: &mut dyn Write,
) -> Result<(), HarnessError> {
    let speeds = modes::campbell::parse_speeds(spec)?;
    let scene = fmu_beam::Scene::load(scene_path)?;
    let origin = scene_path.display().to_string();
    let prefix = output.unwrap_or_else(|| PathBuf::from(format!("{}_campbell", scene.name)));
    let with = |ext: &str| {
        let mut p = prefix.clone().into_os_string();
        p.push(ext);
        PathBuf::from(p)
    };
    let (csv, png) = (with(".csv"), with(".png"));
    // both files are looked at before the first eigenvalue problem
    crate::output_file::check_all([csv.as_path(), &png])?;
    let all = modes::campbell::modes_at_speeds(&scene, &origin, &options, &speeds, jobs)?;
    let frequencies = all
        .iter()
        .map(|m| m.frequencies.iter().copied().take(count).collect())
        .collect();
    let last = all.last();
    let d = modes::campbell::Diagram {
        speeds,
        frequencies,
    };
    crate::output_file::write_atomically(&csv, d.csv().as_bytes())?;
    let title = format!("{}: Campbell diagram", scene.name);
    crate::output_file::write_atomically(&png, &d.png(&title, 800, 560))?;
    let Some(m) = last else {
        return Err(HarnessError::Input {
            origin: "--campbell".into(),
            message: "no speeds".into(),
        });
    };
    let text = format!(
        "Campbell diagram of {} modes at {} speeds from {} to {} rad/s (hub '{}'; joints \
         locked: {}): wrote {} and {}\n",
        d.modes(),
        d.speeds.len(),
        d.speeds[0],
        d.speeds[d.speeds.len() - 1],
        m.hub.as_deref().unwrap_or("?"),
        if m.locked.is_empty() {
            "none".to_string()
        } else {
            m.locked.join(", ")
        },
        csv.display(),
        png.display()
    );
    out.write_all(text.as_bytes()).map_err(stdout_err)
}
