//! A study's work-precision table (CSV, and Markdown with the choice, how sure it is, what
//! limits the error and what the study cost).

use super::estimate::{Ladder, OrderSource};
use super::{Role, Run, Study, NEWTON_PER_HALVING, NEWTON_PROBE};
use std::fmt::Write as _;

/// The work-precision table as CSV: one row per run.
pub fn csv(study: &Study) -> String {
    let mut s = String::from(
        "run,role,step_s,newton_tolerance,mesh,stiffening_switched,steps,newton_iterations,jacobians,work,status,estimated_error",
    );
    for o in &study.outputs {
        let _ = write!(s, ",error_{o}");
    }
    if study.judged() {
        s.push_str(",true_error");
    }
    // the timing last: what differs between runs of the same study
    s.push_str(",cpu_s\n");
    for (i, r) in study.runs.iter().enumerate() {
        let status = match &r.result {
            Ok(_) => "ok".to_string(),
            Err(e) => format!("\"failed: {}\"", e.replace('"', "'")),
        };
        let _ = write!(
            s,
            "{},{},{:e},{:e},\"{}\",{},{},{},{},{:.6},{},{}",
            i + 1,
            r.role.name(),
            r.setting.step,
            r.setting.newton,
            mesh_of(study, r),
            r.setting.stiffening_switched,
            r.counts.steps,
            r.counts.iterations,
            r.counts.jacobians,
            r.work,
            status,
            r.error().map_or(String::new(), |e| format!("{e:.4e}")),
        );
        for e in &r.errors {
            let _ = write!(s, ",{e:.4e}");
        }
        if study.judged() {
            let _ = write!(
                s,
                ",{}",
                r.true_error().map_or(String::new(), |e| format!("{e:.4e}"))
            );
        }
        let _ = writeln!(s, ",{:.6}", r.seconds);
    }
    s
}

fn mesh_of(study: &Study, r: &Run) -> String {
    study.mesh_name(r.setting.mesh).to_string()
}

fn ladder_text(name: &str, l: &Option<Ladder>, nominal: f64) -> String {
    let Some(l) = l else {
        return format!("{name}: not estimated (fewer than two runs)");
    };
    let diffs: Vec<String> = l.differences.iter().map(|d| format!("{d:.2e}")).collect();
    let how = match l.source {
        OrderSource::Observed => format!("observed order {:.2}", l.order),
        OrderSource::Nominal { observed: Some(p) } => format!(
            "observed order {p:.2} is outside 0.5–6 (not in the asymptotic range): \
             the nominal {nominal} used"
        ),
        OrderSource::Nominal { observed: None } => {
            format!("order not observable from two runs: the nominal {nominal} assumed")
        }
        OrderSource::Converged => "converged to rounding".into(),
    };
    format!(
        "{name}: differences of successive runs {} → {how}",
        diffs.join(", ")
    )
}

/// Which share limits the error.
pub fn limit_name(time: f64, mesh: f64, newton: f64) -> &'static str {
    if newton >= time && newton >= mesh {
        "Newton's tolerance"
    } else if time >= mesh {
        "time integration (the step)"
    } else {
        "discretization (the mesh)"
    }
}

/// The report in Markdown: the ladders, the table, the choice, how sure, the limits, the cost.
pub fn markdown(study: &Study) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Accuracy study of {}: {} at a target of {:.0e}\n",
        study.scene,
        study.outputs.join(", "),
        study.target
    );
    let _ = writeln!(
        s,
        "Error: the largest over the grid ({} to {} s every {} s) of |y − y*| / max |y*|, the \
         largest over the outputs (the peer bench's norm). y*: Richardson's extrapolation of \
         the time ladder (fixed steps halved, Newton's tolerance / {NEWTON_PER_HALVING} each \
         time) and of the mesh ladder (elements or substructures doubled, at the step of time \
         level {}), each with its observed order; a run's error is its distance to y*.\n",
        study.start,
        study.stop,
        study.comm,
        study.mesh_step_level + 1
    );
    let _ = writeln!(
        s,
        "- {}\n- {}\n",
        ladder_text("time", &study.time, super::TIME_ORDER),
        ladder_text("mesh", &study.mesh, super::MESH_ORDER)
    );
    let _ = write!(
        s,
        "| run | ladder | step (s) | Newton tol. | mesh | work | CPU s | steps | Newton it. | estimated error |"
    );
    for o in &study.outputs {
        let _ = write!(s, " {o} |");
    }
    if study.judged() {
        s.push_str(" true error |");
    }
    let _ = write!(s, "\n|---|---|---|---|---|---|---|---|---|---|");
    for _ in &study.outputs {
        s.push_str("---|");
    }
    if study.judged() {
        s.push_str("---|");
    }
    s.push('\n');
    for (i, r) in study.runs.iter().enumerate() {
        let mesh = if r.setting.stiffening_switched {
            format!("{}, stiffening switched", mesh_of(study, r))
        } else {
            mesh_of(study, r)
        };
        let err = match (&r.result, r.error()) {
            (Err(e), _) => format!("failed: {e}"),
            (Ok(_), Some(e)) => format!("{e:.2e}"),
            _ => String::new(),
        };
        let _ = write!(
            s,
            "| {} | {} | {:.3e} | {:.0e} | {mesh} | {:.3} | {:.3} | {} | {} | {err} |",
            i + 1,
            r.role.name(),
            r.setting.step,
            r.setting.newton,
            r.work,
            r.seconds,
            r.counts.steps,
            r.counts.iterations
        );
        for e in &r.errors {
            let _ = write!(s, " {e:.2e} |");
        }
        if let Some(t) = r.true_error() {
            let _ = write!(s, " {t:.2e} |");
        } else if study.judged() {
            s.push_str(" |");
        }
        s.push('\n');
    }
    s.push('\n');
    match &study.choice {
        None => {
            let best = study
                .runs
                .iter()
                .filter_map(|r| r.error().map(|e| (e, r)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let _ = writeln!(
                s,
                "## Target not met\n\nNo setting of the ladders meets {:.0e} with a safety \
                 factor of {}{}. Extend them \
                 (--levels, --mesh-levels, --step) or raise the budget.\n",
                study.target,
                study.margin,
                best.map_or(String::new(), |(e, r)| format!(
                    " (smallest estimated error {e:.2e}, at h = {:.2e} s, {})",
                    r.setting.step,
                    mesh_of(study, r)
                ))
            );
        }
        Some(c) => {
            let run = &study.runs[c.run];
            let est = run.error().unwrap_or(f64::NAN);
            let _ = writeln!(
                s,
                "## Cheapest settings for {:.0e}\n\nThe cheapest setting whose predicted error \
                 times {} meets the target (a safety factor: {}). A fixed step of {:e} s, Newton's tolerance \
                 {:.0e}, mesh {}: predicted error {:.2e} (its time error {:.2e} and mesh error {:.2e} \
                 added over time), \
                 estimated from its run {est:.2e}, work {:.3} (predicted {:.3}; {:.3} CPU s).\n\nIn the \
                 scene: `[solver] adaptive = false`, `max_step = {:e}`, `tolerance = {:.0e}`; \
                 beams: {}.\n",
                study.target,
                study.margin,
                if study.margin < 2.0 {
                    "every ladder's order observed"
                } else {
                    "an order assumed"
                },
                c.setting.step,
                c.setting.newton,
                mesh_of(study, run),
                c.predicted,
                c.time_share,
                c.mesh_share,
                run.work,
                c.predicted_work,
                run.seconds,
                c.setting.step,
                c.setting.newton,
                mesh_of(study, run)
            );
            if c.setting != c.ladder {
                let _ = writeln!(
                    s,
                    "Relaxed from the ladder's setting (h = {:e} s, Newton's tolerance {:.0e}): \
                     the largest step up to the coarser rung that the time ladder's order \
                     predicts to meet, at the coarsest rung's Newton tolerance; kept because \
                     its run's estimated error times {} meets the target.\n",
                    c.ladder.step, c.ladder.newton, study.margin
                );
            }
            let _ = writeln!(s, "## How sure\n");
            match c.finer {
                Some((i, d)) => {
                    let expected = c.expected_difference;
                    let ratio = d / expected;
                    let verdict = if (1.0 / 3.0..=3.0).contains(&ratio) {
                        "consistent: the estimate holds within 3×"
                    } else {
                        "NOT consistent: the ladders are not in their asymptotic range; \
                         trust the measured difference, not the estimate"
                    };
                    let _ = writeln!(
                        s,
                        "Against a finer run (step {:e} s, mesh {}): measured difference \
                         {d:.2e}, expected {expected:.2e} if the estimate is right (ratio \
                         {ratio:.2}): {verdict}.\n",
                        study.runs[i].setting.step,
                        mesh_of(study, &study.runs[i])
                    );
                }
                None => {
                    let _ = writeln!(s, "The finer run did not run (budget or failure).\n");
                }
            }
            if let Some(t) = run.true_error() {
                let _ = writeln!(
                    s,
                    "Against the reference: true error {t:.2e}, estimated {est:.2e} (ratio \
                     {:.2}), predicted before the run {:.2e} (ratio {:.2}); the target is {}.\n",
                    est / t,
                    c.predicted,
                    c.predicted / t,
                    if t <= study.target { "met" } else { "NOT met" }
                );
            }
            let newton = c.newton_share.unwrap_or(0.0);
            let _ = writeln!(
                s,
                "## What limits the error\n\n- time integration: {:.2e}\n- discretization: \
                 {:.2e}\n- Newton's tolerance: {} (the difference at tolerance / {NEWTON_PROBE})\n\
                 \nThe limit is **{}**.",
                c.time_share,
                c.mesh_share,
                c.newton_share
                    .map_or("not measured".into(), |n| format!("{n:.2e}")),
                limit_name(c.time_share, c.mesh_share, newton)
            );
            match &c.stiffening_change {
                Some(Ok(d)) => {
                    let _ = writeln!(
                        s,
                        "\nSwitching every flexible beam's geometric stiffening changes the \
                         outputs by {d:.2e}: {}",
                        if *d > study.target {
                            "more than the target, so that choice of physics matters more \
                             than the numerics here (keep what the scene's loads call for)"
                        } else {
                            "within the target"
                        }
                    );
                }
                Some(Err(e)) => {
                    let _ = writeln!(s, "\nGeometric stiffening could not be switched: {e}");
                }
                None => {}
            }
            s.push('\n');
        }
    }
    if let Some(why) = &study.incomplete {
        let _ = writeln!(s, "## INCOMPLETE\n\n{why}.\n");
    }
    let _ = writeln!(
        s,
        "## Cost\n\n{} runs{}, work {:.2} (counted: what the study ranks settings and keeps \
         to its budget by), {:.2} CPU s, {:.2} s wall, {} run{} at once.",
        study.runs.len() + study.earlier_runs,
        if study.earlier_runs > 0 {
            format!(
                " ({} of them in the other study of the notes, not in the table)",
                study.earlier_runs
            )
        } else {
            String::new()
        },
        study.work,
        study.cpu_seconds,
        study.wall_seconds,
        study.jobs,
        if study.jobs == 1 { "" } else { "s" }
    );
    if study.jobs > 1 {
        let _ = writeln!(
            s,
            "- run ahead and not asked for: {} runs, {:.2} CPU s (not in the table); runs ahead \
             paused for an asked one: {}",
            study.unused.0, study.unused.1, study.pauses
        );
    }
    for n in &study.notes {
        let _ = writeln!(s, "- {n}");
    }
    s
}

/// The study in a few numbers, as JSON (`study.json`, read by `fmu-bench exhaustive`): the
/// target, the safety factor, whether it is complete, the choice (its setting, counted work,
/// errors) and the study's own cost.
pub fn json(study: &Study) -> String {
    let choice = study.choice.as_ref().map(|c| {
        let run = &study.runs[c.run];
        serde_json::json!({
            "step": c.setting.step,
            "newton": c.setting.newton,
            "mesh": study.mesh_name(c.setting.mesh),
            "work": run.work,
            "cpu_s": run.seconds,
            "predicted_error": c.predicted,
            "estimated_error": run.error(),
            "true_error": run.true_error(),
        })
    });
    let v = serde_json::json!({
        "scene": study.scene,
        "outputs": study.outputs,
        "target": study.target,
        "margin": study.margin,
        "incomplete": study.incomplete,
        "choice": choice,
        "runs": study.runs.len() + study.earlier_runs,
        "work": study.work,
        "cpu_s": study.cpu_seconds,
        "wall_s": study.wall_seconds,
        "jobs": study.jobs,
        "unused_runs": study.unused.0,
        "unused_cpu_s": study.unused.1,
        "paused_runs": study.pauses,
    });
    format!("{v:#}\n")
}

/// Whether a run is one of the ladders' (the chart's points).
pub fn on_ladder(r: &Run) -> bool {
    matches!(r.role, Role::Time | Role::Mesh | Role::Chosen | Role::Finer)
}
