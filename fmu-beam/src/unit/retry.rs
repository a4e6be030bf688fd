//! Whether a master may retry a step that failed with a Discard, the same for FMI 2.0 and 3.0:
//! not when the model is out of its range ([`EngineError::ends_run`]), nor when the master
//! repeats the very step that failed (the engine is deterministic, so it would fail the same
//! way, and a master such as fmpy's `simulate_fmu` would loop forever).

use crate::error::EngineError;

/// The last failed step a retry may overcome, as (t, h).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Retry {
    last_discard: Option<(f64, f64)>,
}

impl Retry {
    /// A step passed, or the state was set or reset: any step may be tried again.
    pub fn clear(&mut self) {
        self.last_discard = None;
    }

    /// After the step (t, h) failed with `e` (a Discard): why no retry can get past it, or
    /// None (a smaller step may; this step is remembered).
    pub fn judge(&mut self, e: &EngineError, t: f64, h: f64) -> Option<&'static str> {
        if e.ends_run() {
            Some("a smaller step cannot get past this")
        } else if self.last_discard == Some((t, h)) {
            Some(
                "the master repeated the step that failed, with the same size; the unit is \
                 deterministic, so it fails the same way (a retry needs a smaller step)",
            )
        } else {
            self.last_discard = Some((t, h));
            None
        }
    }
}
