"""The lag-hinge rotor split at the hinge (scenes/hinged_blade_hub.toml + hinged_blade_arm.toml),
joined by `fmu-harness cosim` [[joint]], against the monolithic unit (scenes/hinged_blade.toml):
the hub's inertia swept (`hub.rho`) from 0.01x to 100x, beside explicit Gauss-Seidel
(the blade in motion causality, hinged_blade_arm_driven.toml, its hinge position interpolated,
the reaction held), and the communication step swept at the scene's own inertia. Writes
build/hinged_blade/hub_sweep.{md,png} (and the plot into examples/hinged_blade/ with --readme).

    python hub_sweep.py [--readme]
"""

import argparse
import re
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

ROOT = Path(__file__).resolve().parents[2]
HARNESS = ROOT / "target" / "release" / "fmu-harness"
FMUS = (ROOT / "build" / "fmus").resolve()
OUT = ROOT / "build" / "hinged_blade"
RHO = 7800.0          # hub density: J_hub = rho A e^3 / 3 = 0.0208 kg m^2
BLADE_J = 0.108 * ((0.2 + 0.5) ** 2 + 1.0 / 12.0)  # blade about the axis, radial: 0.0619 kg m^2
FACTORS = [0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0]
STEPS = [4e-3, 2e-3, 1e-3, 5e-4]
STOP = 1.0
OUTPUTS = ["axis.angle", "blade.tip.deflection"]


def joint_text(step, rho):
    start = f'"solver.adaptive" = false, "solver.max_step" = {step!r}'
    return f"""stop_time = {STOP!r}
step = {{ size = {step!r} }}
outputs = ["hub.axis.angle", "blade.blade.tip.deflection"]
[[joint]]
name = "hinge"
type = "revolute"
frames = ["hub.hinge", "blade.hinge"]
[[unit]]
name = "hub"
fmu = "{FMUS / 'hinged_blade_hub.fmu'}"
start = {{ "hub.rho" = {rho!r}, {start} }}
[[unit]]
name = "blade"
fmu = "{FMUS / 'hinged_blade_arm.fmu'}"
start = {{ {start} }}
"""


def explicit_text(step, rho):
    """Gauss-Seidel, hub first with the blade's reaction held, then the blade with the hinge
    position interpolated (quadratic), as the slider-crank's explicit baseline."""
    return f"""stop_time = {STOP!r}
step = {{ size = {step!r} }}
algorithm = "gauss-seidel"
order = ["hub", "blade"]
extrapolation = "quadratic"
outputs = ["hub.axis.angle", "blade.blade.tip.deflection"]
connections = [
  "hub.hinge.x -> blade.pin_x.drive.position",
  "hub.hinge.y -> blade.pin_y.drive.position",
  {{ from = "blade.pin_x.force", to = "hub.hinge.fx", factor = -1.0, extrapolation = "none" }},
  {{ from = "blade.pin_y.force", to = "hub.hinge.fy", factor = -1.0, extrapolation = "none" }},
]
[[unit]]
name = "hub"
fmu = "{FMUS / 'hinged_blade_hub.fmu'}"
start = {{ "hub.rho" = {rho!r} }}
[[unit]]
name = "blade"
fmu = "{FMUS / 'hinged_blade_arm_driven.fmu'}"
"""


def harness(text):
    with tempfile.TemporaryDirectory() as d:
        sysfile, out = Path(d) / "system.toml", Path(d) / "out.csv"
        sysfile.write_text(text)
        run = subprocess.run([HARNESS, "cosim", sysfile, "-o", out], capture_output=True, text=True)
        if run.returncode != 0:
            m = re.search(r"at t = ([0-9.eE+-]+)", run.stderr)
            return None, (float(m.group(1)) if m else float("nan")), run.stderr
        return np.loadtxt(out, delimiter=",", skiprows=1), None, run.stdout


def monolithic(step, rho, fixed):
    start = {"hub.rho": rho}
    if fixed:
        start.update({"solver.adaptive": False, "solver.max_step": step})
    r = simulate_fmu(FMUS / "hinged_blade.fmu", stop_time=STOP, output_interval=step,
                     output=OUTPUTS, start_values=start)
    return np.c_[r[OUTPUTS[0]], r[OUTPUTS[1]]]


def per_step(text):
    m = re.search(r"joints: ([0-9.]+) iterations and ([0-9.]+) restores per step, ([0-9.]+) unit "
                  r"steps per step \((\d+) in all\), (\d+) refused", text)
    return (float(m[1]), float(m[3]), int(m[5])) if m else (np.nan, np.nan, -1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--readme", action="store_true")
    a = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    h = 1e-3
    lines = [f"## Hub inertia swept (h = 1 ms, {STOP} s): max error against the monolithic unit", "",
             "| hub density / scene | J_hub / J_blade | joint: hub angle (rad) | joint: tip deflection (m) | "
             "iterations / step | refused steps | explicit Gauss-Seidel: hub angle (rad) |",
             "|---|---|---|---|---|---|---|"]
    sweep = {}
    for f in FACTORS:
        rho = RHO * f
        ratio = 0.0208 * f / BLADE_J
        data, failed, text = harness(joint_text(h, rho))
        mono = monolithic(h, rho, fixed=True)
        if data is not None:
            e = np.abs(data[:, 1:] - mono).max(axis=0)
            it, steps, refused = per_step(text)
            joint = f"| {e[0]:.2e} | {e[1]:.2e} | {it:.2f} | {refused} |"
            sweep[(f, "joint")] = e[0]
        else:
            joint = f"| fails at {failed} | | | |"
            sweep[(f, "joint")] = None
        exp, efailed, _ = harness(explicit_text(h, rho))
        if exp is not None:
            ee = np.abs(exp[:, 1] - monolithic(h, rho, fixed=False)[:, 0]).max()
            explicit = f"{ee:.2e}"
            sweep[(f, "explicit")] = ee
        else:
            explicit = f"fails at t = {efailed}"
            sweep[(f, "explicit")] = None
        lines.append(f"| {f:g} | {ratio:.3g} {joint} {explicit} |")
        print(lines[-1], flush=True)
    lines += ["", f"## Communication step swept (the scene's hub, {STOP} s): max error against the monolithic "
              "unit at the same steps", "",
              "| h | hub angle (rad) | tip deflection (m) | iterations / step | unit steps / step |",
              "|---|---|---|---|---|"]
    for step in STEPS:
        data, failed, text = harness(joint_text(step, RHO))
        if data is None:
            lines.append(f"| {step * 1e3:g} ms | fails at {failed} | | | |")
            continue
        e = np.abs(data[:, 1:] - monolithic(step, RHO, fixed=True)).max(axis=0)
        it, us, _ = per_step(text)
        lines.append(f"| {step * 1e3:g} ms | {e[0]:.2e} | {e[1]:.2e} | {it:.2f} | {us:.2f} |")
        print(lines[-1], flush=True)
    (OUT / "hub_sweep.md").write_text("\n".join(lines) + "\n")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    ratios = np.array(FACTORS) * 0.0208 / BLADE_J
    for label, style in [("joint", "o-"), ("explicit", "s--")]:
        pts = [(r, sweep[(f, label)]) for f, r in zip(FACTORS, ratios) if sweep[(f, label)] is not None]
        fails = [r for f, r in zip(FACTORS, ratios) if sweep[(f, label)] is None]
        name = ("joint coupling (vs monolithic, same steps)" if label == "joint"
                else "explicit Gauss-Seidel, quadratic (vs monolithic)")
        line, = ax.loglog(*zip(*pts), style, label=name) if pts else ax.loglog([], [], style, label=name)
        ax.plot(fails, [1.0] * len(fails), "x", color=line.get_color(), ms=9)
    ax.set_xlabel("hub inertia / blade inertia about the axis")
    ax.set_ylabel("max |hub angle error| (rad), x = the run fails")
    ax.set_title(f"Lag-hinge rotor split at the hinge, h = 1 ms, {STOP} s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "hub_sweep.png", dpi=110)
    if a.readme:
        fig.savefig(Path(__file__).parent / "hub_sweep.png", dpi=110)
    print((OUT / "hub_sweep.md").read_text())


if __name__ == "__main__":
    main()
