//! The study re-centred on another mesh: where the first study's choice is a mesh other than
//! the scene's, or the halved mesh's own error leaves room for the step's, the whole study runs
//! again with that mesh as the scene's, and the cheaper certified choice is kept.

use super::pool::Pool;
use super::runner::scene_at;
use super::{recentre_mesh, study_of, Options, Role, Setting, Study};
use fmu_beam::Scene;

/// The ladders measure the step's error at the scene's mesh and add each mesh's error at one
/// step; at another mesh the step's own error may differ (C2: a finer mesh rings less after
/// the release, and the first study's step is smaller than its mesh needs; C3's elastic
/// crank: 2 elements do not carry the modes 3 ring in). Where the choice is another mesh, or
/// the halved mesh's own error times the safety factor is within the target, the study runs
/// again with that mesh as the scene's, in what is left of the budget, and the cheaper of the
/// two choices (each certified by its own ladders, finer run and factor) is kept, the other
/// named in a note.
pub(super) fn recentred(
    base: &Scene,
    opts: &Options,
    mut first: Study,
    pool: &Pool,
    interrupted: &dyn Fn() -> bool,
) -> Study {
    let Some(c) = first.choice.as_ref() else {
        return first;
    };
    if first.incomplete.is_some() {
        return first;
    }
    // the chosen mesh, else the halved one where its own error leaves room for the step's
    let halved_error = first
        .runs
        .iter()
        .find(|r| r.role == Role::Mesh && r.setting.mesh == -1)
        .and_then(|r| r.error());
    let Some(m) = recentre_mesh(c.setting.mesh, halved_error, first.margin, first.target) else {
        pool.forget(&[]);
        return first;
    };
    let at_mesh = Setting {
        step: base.solver.max_step,
        newton: base.solver.tolerance,
        mesh: m,
        stiffening_switched: false,
    };
    let Ok(mut moved) = scene_at(base, &at_mesh) else {
        return first;
    };
    moved.solver.adaptive = base.solver.adaptive;
    let mut o = opts.clone();
    o.max_runs = opts.max_runs.saturating_sub(first.runs.len());
    o.max_work = opts.max_work - first.work;
    let mesh = first.mesh_name(m).to_string();
    let first_work = first.runs[c.run].work;
    let said = |s: &Study| {
        s.choice.as_ref().map_or("no choice".to_string(), |c| {
            format!(
                "h = {:e} s, mesh {}, estimated {:.2e}, work {:.3}",
                c.setting.step,
                s.mesh_name(c.setting.mesh),
                c.predicted,
                s.runs[c.run].work
            )
        })
    };
    let second = if o.max_runs == 0 || o.max_work <= 0.0 {
        Err("the budget is spent".to_string())
    } else {
        // its mesh ladder probably runs at the step the first one's did
        let hint = first
            .runs
            .iter()
            .find(|r| r.role == Role::Mesh)
            .map(|r| r.setting.step);
        study_of(&moved, &o, pool, interrupted, false, hint).map_err(|e| e.to_string())
    };
    match second {
        Ok(mut second)
            if second
                .choice
                .as_ref()
                .is_some_and(|c2| second.runs[c2.run].work < first_work)
                && second.incomplete.is_none() =>
        {
            let note = format!(
                "re-centred: the first study (at the scene's mesh, {} runs, work {:.2}) chose {}; \
                 this study, with {mesh} as the scene's mesh, chose a cheaper setting",
                first.runs.len(),
                first.work,
                said(&first)
            );
            second.notes.insert(0, note);
            second.earlier_runs = first.runs.len();
            second.work += first.work;
            second.cpu_seconds += first.cpu_seconds;
            second.wall_seconds += first.wall_seconds;
            second
        }
        Ok(second) => {
            first.earlier_runs += second.runs.len();
            first.notes.push(format!(
                "re-centred on {mesh} ({} runs, work {:.2}): {}{}; kept",
                second.runs.len(),
                second.work,
                said(&second),
                if second.incomplete.is_some() {
                    ", INCOMPLETE (its wall-clock safety stop fired)"
                } else {
                    ", not cheaper"
                }
            ));
            for n in second.notes.iter().filter(|n| n.contains("safety stop")) {
                first.notes.push(n.clone());
            }
            first.incomplete = first.incomplete.take().or(second.incomplete);
            first.work += second.work;
            first.cpu_seconds += second.cpu_seconds;
            first.wall_seconds += second.wall_seconds;
            first
        }
        Err(e) => {
            first
                .notes
                .push(format!("re-centred on {mesh}: not run ({e})"));
            first
        }
    }
}
