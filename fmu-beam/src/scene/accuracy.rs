//! The scene's `[accuracy]`: the accuracy its solver settings and discretization were tuned for
//! (issue 34), a statement `fmu-harness explain` prints and the FMU's documentation carries.
//! The values are checked here; that `output` names an output of the unit is checked where the
//! variables are known (`fmu-harness` `package` and `explain`).

use super::rules as r;
use super::validate::{Checker, SceneError};
use super::Scene;
use serde::{Deserialize, Serialize};

/// What the scene's settings were tuned for: the largest error of one output over the
/// DefaultExperiment, relative to that output's largest magnitude, is at most `target`
/// (`fmu-harness accuracy SCENE --output OUTPUT --target TARGET` chose the settings and
/// estimated `estimate`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct AccuracySpec {
    /// The output the accuracy is stated for, as the FMU names it (`slider.position`,
    /// `beam.tip.deflection`).
    pub output: String,
    /// The largest error over the run, relative to the output's largest magnitude, that the
    /// settings were tuned to stay within.
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "1")))]
    pub target: f64,
    /// The accuracy study's estimate of that error for these settings (at most `target`).
    #[cfg_attr(feature = "schema", schemars(extend("x-unit" = "1")))]
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimate: Option<f64>,
}

impl AccuracySpec {
    /// One paragraph for `explain` and the FMU's documentation.
    pub fn statement(&self, scene: &Scene) -> String {
        let e = &scene.experiment;
        let estimate = match self.estimate {
            Some(x) => format!(" (the accuracy study's estimate for these settings: {x:.1e})"),
            None => String::new(),
        };
        format!(
            "Accuracy: these settings were tuned so that the largest error of {} over the \
             DefaultExperiment ({} s to {} s), relative to its largest magnitude, is at most \
             {:e}{estimate}. `fmu-harness accuracy` re-estimates it for other targets, outputs \
             or settings; other outputs and other experiments are not covered by this statement.\n",
            self.output, e.start_time, e.stop_time, self.target
        )
    }
}

/// `accuracy`: a target in (0, 1), an estimate in [0, target], an output of a named part.
pub(super) fn validate(ck: &Checker, scene: &Scene) -> Result<(), SceneError> {
    let Some(a) = &scene.accuracy else {
        return Ok(());
    };
    ck.positive("accuracy.target", a.target)?;
    if a.target >= 1.0 {
        return Err(ck.fail(&r::ACCURACY_TARGET, "accuracy.target", a.target));
    }
    if let Some(x) = a.estimate {
        ck.non_negative("accuracy.estimate", x)?;
        if x > a.target {
            return Err(ck.fail(&r::ACCURACY_ESTIMATE, "accuracy.estimate", x));
        }
    }
    let part = a.output.split_once('.').map(|(p, _)| p);
    let named = |p: &str| {
        scene.beams.iter().any(|b| b.name == p)
            || scene.bodies.iter().any(|b| b.name == p)
            || scene.joints.iter().any(|j| j.name == p)
            || scene.loads.iter().any(|l| l.name == p)
    };
    if !part.is_some_and(named) {
        return Err(ck.fail(
            &r::ACCURACY_OUTPUT,
            "accuracy.output",
            format!("{:?}", a.output),
        ));
    }
    Ok(())
}
