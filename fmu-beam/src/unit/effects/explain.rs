//! The explanation of a [`Resolution`] as text: one line per decision with its reason and its
//! share of a step's cost, then the shape outputs and what reading them costs (what
//! `fmu-harness explain` prints and the FMU carries in `documentation/`).

use super::*;

/// Widest column of the tables (characters): a longer cell runs past its column rather than
/// widening it (a format width above 65 535 panics).
const WIDEST: usize = 100;

impl Resolution {
    /// The explanation as text: one line per decision, then the cost model's total.
    pub fn explain(&self, scene: &Scene) -> String {
        let mut s = format!(
            "Effects of scene '{}' (effects = {}):\n\n",
            scene.name, self.mode
        );
        let w = self
            .decisions
            .iter()
            .map(|d| d.effect.len() + d.subject.len() + 3)
            .max()
            .unwrap_or(10)
            .min(WIDEST);
        let ws = self
            .decisions
            .iter()
            .map(|d| d.setting.len())
            .max()
            .unwrap_or(3)
            .min(WIDEST);
        s += &format!(
            "{:<w$}  {:<ws$}  {:>6}  why\n",
            "effect (subject)", "setting", "cost"
        );
        for d in &self.decisions {
            let name = format!("{} ({})", d.effect, d.subject);
            s += &format!(
                "{name:<w$}  {:<ws$}  {:>5.1}%  {}\n",
                d.setting,
                100.0 * d.cost_share,
                d.why
            );
        }
        let spatial = self
            .decisions
            .iter()
            .any(|d| d.effect == "formulation" && d.setting == "spatial");
        s += &self.explain_shape(scene, spatial);
        if spatial {
            s += "\ncost: no operation-count model for the 3D element (shares shown as 0); \
                  `make bench` measures the time.\n";
            return s;
        }
        s += &format!(
            "\ncost: the share of the operations of one step (residual, tangents, LU of the \
             iteration matrix) that the effect adds, from an operation count of the resolved \
             system ({} coordinates); `make bench` measures the time.\n",
            coordinates(scene, &self.effects)
        );
        s
    }
}

impl Resolution {
    /// The shape outputs (`crate::unit::shape`): what each beam offers and what reading them costs.
    fn explain_shape(&self, scene: &Scene, spatial: bool) -> String {
        let coords = if scene.is_3d() { 3 } else { 2 };
        let rows: Vec<(String, String, String)> = scene
            .beams
            .iter()
            .zip(&self.effects.beams)
            .map(|(b, e)| {
                let n = crate::unit::shape::stations(b, e.rigid).len();
                let setting = if n == 0 {
                    "off".to_string()
                } else {
                    format!("{n} points, {} outputs", coords * (n + 1))
                };
                let cost = if n == 0 {
                    "none".to_string()
                } else if spatial {
                    format!("{} point evaluations per read of all", coords * n)
                } else {
                    let total = step_cost(scene, &self.effects);
                    format!(
                        "reading all once: {:.2}% of an internal step",
                        100.0 * shape_read_cost(b, e) / total
                    )
                };
                (format!("shape ({})", b.name), setting, cost)
            })
            .collect();
        if rows.is_empty() {
            return String::new();
        }
        let w = rows
            .iter()
            .map(|r| r.0.len())
            .max()
            .unwrap_or(0)
            .min(WIDEST);
        let ws = rows
            .iter()
            .map(|r| r.1.len())
            .max()
            .unwrap_or(0)
            .min(WIDEST);
        let mut s = String::from(
            "\noutputs computed only when read (a step that nobody reads them after costs nothing \
             more); `shape_points` sets the points, 0 none:\n",
        );
        for (name, setting, cost) in rows {
            s += &format!("{name:<w$}  {setting:<ws$}  {cost}\n");
        }
        s
    }
}
