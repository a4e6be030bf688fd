"""The split slider-crank joined at the pin by `fmu-harness cosim` [[joint]] (the interface-force
coupling), measured: slider error against the monolithic unit over 0.3 s and over C3's 1.6 s
(torque cut at 0.7 s) for h = 4, 2, 1, 0.5 ms, with the observed order; the crank density swept
from 0.05x to 20x its C3 value beside the explicit schemes of study.py; the cost per
communication step and the CPU time against explicit Gauss-Seidel. Writes
build/split/joint_study.{md,csv,png} (and the plot into examples/split_slider_crank/ with --readme).

    python joint_study.py [--readme]
"""

import argparse
import csv
import re
import resource
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

import study  # the explicit schemes (system_text, SCHEMES)

ROOT = Path(__file__).resolve().parents[2]
HARNESS = ROOT / "target" / "release" / "fmu-harness"
FMUS = (ROOT / "build" / "fmus").resolve()
OUT = ROOT / "build" / "split"
RHO = 2770.0
STEPS = [4e-3, 2e-3, 1e-3, 5e-4]
FACTORS = [0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0]
FINE = 1.25e-5  # the converged reference: the monolithic unit at this fixed step


def joint_text(step, stop, rho):
    start = f'"solver.adaptive" = false, "solver.max_step" = {step!r}'
    return f"""stop_time = {stop!r}
step = {{ size = {step!r} }}
outputs = ["crank.crank.tip.y", "rod.slider.position"]
[[joint]]
name = "pin"
type = "revolute"
frames = ["crank.pin", "rod.pin"]
[[unit]]
name = "crank"
fmu = "{FMUS / 'slider_crank_split_crank.fmu'}"
start = {{ "crank.rho" = {rho!r}, {start} }}
[[unit]]
name = "rod"
fmu = "{FMUS / 'slider_crank_split_rod_force.fmu'}"
start = {{ {start} }}
"""


def harness(text):
    """Runs `fmu-harness cosim` on system text: (data or None, failure time, stdout+stderr, CPU s)."""
    with tempfile.TemporaryDirectory() as d:
        sysfile, out = Path(d) / "system.toml", Path(d) / "out.csv"
        sysfile.write_text(text)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        run = subprocess.run([HARNESS, "cosim", sysfile, "-o", out], capture_output=True, text=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        if run.returncode != 0:
            m = re.search(r"at t = ([0-9.eE+-]+)", run.stderr)
            return None, (float(m.group(1)) if m else float("nan")), run.stderr.strip(), cpu
        return np.loadtxt(out, delimiter=",", skiprows=1), None, run.stdout, cpu


def monolithic(step, stop, rho, fixed=None):
    """Slider position of the monolithic unit on the communication grid: with a fixed internal
    step `fixed` (the units' own step in the coupled run), or as packaged (error control)."""
    start = {"crank.rho": rho}
    if fixed:
        start.update({"solver.adaptive": False, "solver.max_step": fixed})
    r = simulate_fmu(FMUS / "slider_crank.fmu", stop_time=stop, output_interval=step,
                     output=["slider.position"], start_values=start)
    return r["slider.position"]


def counts(text):
    """Per-step figures from the cosim summary."""
    m = re.search(r"joints: ([0-9.]+) iterations and ([0-9.]+) restores per step, ([0-9.]+) unit "
                  r"steps per step \((\d+) in all\), (\d+) refused", text)
    return dict(iterations=float(m[1]), restores=float(m[2]), unit_steps=float(m[3]),
                refused=int(m[5])) if m else {}


def order(errors):
    e = np.array(errors)
    return np.log2(e[:-1] / e[1:])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--readme", action="store_true", help="also write the plot into the example")
    a = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    lines, rows = [], []

    # 1. Accuracy against the monolithic unit, C3's masses
    fine = {stop: monolithic(FINE, stop, RHO, fixed=FINE) for stop in (0.3, 1.6)}
    lines += ["## C3's own masses: max |slider error| (m)", "",
              "| stop | h | against the monolithic unit, same steps | against the converged reference | "
              "the monolithic unit against the converged reference | iterations / step | unit steps / step | refused steps |",
              "|---|---|---|---|---|---|---|---|"]
    acc = {}
    for stop in (0.3, 1.6):
        for h in STEPS:
            data, failed, text, cpu = harness(joint_text(h, stop, RHO))
            mono = monolithic(h, stop, RHO, fixed=h)
            ref = fine[stop][:: int(round(h / FINE))]
            if data is None:
                lines.append(f"| {stop} | {h:g} | fails at t = {failed} | | | | | |")
                continue
            e_mono = np.abs(data[:, 2] - mono).max()
            e_ref = np.abs(data[:, 2] - ref).max()
            e_mref = np.abs(mono - ref).max()
            cut = data[:, 0] < 0.69
            c = counts(text)
            acc[(stop, h)] = (e_mono, e_ref, e_mref, np.abs(data[cut, 2] - ref[cut]).max())
            rows.append(dict(part="accuracy", stop=stop, step=h, factor=1.0, scheme="joint",
                             error_mono=e_mono, error_reference=e_ref, cpu=cpu, **c))
            lines.append(f"| {stop} s | {h * 1e3:g} ms | {e_mono:.2e} | {e_ref:.2e} | {e_mref:.2e} | "
                         f"{c['iterations']:.2f} | {c['unit_steps']:.2f} | {c['refused']} |")
            print(f"accuracy stop {stop} h {h}: {e_mono:.2e} (monolithic), {e_ref:.2e} (reference)",
                  flush=True)
    for stop, col, what in [(0.3, 1, "over 0.3 s"), (1.6, 3, "over 1.6 s, before the cut (t < 0.69 s)"),
                            (1.6, 1, "over 1.6 s")]:
        e = [acc[(stop, h)][col] for h in STEPS if (stop, h) in acc]
        if len(e) == len(STEPS):
            lines.append(f"\nObserved order against the converged reference {what}, h = 4 → 2 → 1 → 0.5 ms: "
                         + ", ".join(f"{p:.2f}" for p in order(e)))

    # 2. Crank density swept, h = 1 ms, 0.3 s: the joint coupling and the explicit schemes
    h, stop = 1e-3, 0.3
    lines += ["", "## Crank density swept (h = 1 ms, 0.3 s): max |slider error| (m) against the monolithic unit",
              "", "| crank density / C3 | joint (same steps) | joint over 1.6 s | "
              + " | ".join(s[0] for s in study.SCHEMES) + " |",
              "|---|---|---|" + "---|" * len(study.SCHEMES)]
    sweep = {}
    for f in FACTORS:
        rho = RHO * f
        data, failed, _, _ = harness(joint_text(h, stop, rho))
        e = np.abs(data[:, 2] - monolithic(h, stop, rho, fixed=h)).max() if data is not None else None
        long, long_failed, _, _ = harness(joint_text(h, 1.6, rho))
        e_long = (np.abs(long[:, 2] - monolithic(h, 1.6, rho, fixed=h)).max()
                  if long is not None else None)
        sweep[(f, "joint")] = e
        cells = [f"{e:.2e}" if e is not None else f"fails at {failed}",
                 f"{e_long:.2e}" if e_long is not None else f"fails at {long_failed}"]
        ref = monolithic(h, stop, rho)
        for label, alg, ext in study.SCHEMES:
            r = study.errors(h, stop, alg, ext, rho, np.c_[np.zeros_like(ref), ref, ref])
            sweep[(f, label)] = r["slider"] if r["ok"] else None
            cells.append(f"{r['slider']:.2e}" if r["ok"] else f"fails at {r['failed_at']:g}")
        lines.append(f"| {f:g} | " + " | ".join(cells) + " |")
        rows.append(dict(part="sweep", stop=stop, step=h, factor=f, scheme="joint",
                         error_mono=e if e is not None else np.nan))
        print(f"factor {f}: joint {cells[0]}, 1.6 s {cells[1]}, explicit {cells[2:]}", flush=True)

    # 3. Cost: CPU against explicit Gauss-Seidel where it works (20x denser crank)
    f = 20.0
    cpu = {"joint": [], "gs": []}
    for _ in range(3):
        cpu["joint"].append(harness(joint_text(h, stop, RHO * f))[3])
        cpu["gs"].append(harness(study.system_text(h, stop, "gauss-seidel", "quadratic", RHO * f))[3])
    _, _, text, _ = harness(joint_text(h, stop, RHO * f))
    c = counts(text)
    jm, gm = np.median(cpu["joint"]), np.median(cpu["gs"])
    lines += ["", f"## Cost (h = 1 ms, 0.3 s, crank {f:g}x denser, where explicit Gauss-Seidel works)", "",
              f"Joint coupling: {c['iterations']:.2f} iterations (one fmi2DoStep of each unit each), "
              f"{c['restores']:.2f} restores (rollbacks) and {c['unit_steps']:.2f} unit steps per "
              f"communication step; CPU {jm:.3f} s against {gm:.3f} s for explicit Gauss-Seidel with "
              f"quadratic interpolation (units with error control, as in study.py): {jm / gm:.1f}x "
              "(median of 3, the harness process's user + system time)."]

    (OUT / "joint_study.md").write_text("\n".join(lines) + "\n")
    with open(OUT / "joint_study.csv", "w", newline="") as fh:
        keys = sorted({k for r in rows for k in r})
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(12, 4.4))
    for stop, marker in [(0.3, "o"), (1.6, "s")]:
        hs = [h for h in STEPS if (stop, h) in acc]
        ax0.loglog(hs, [acc[(stop, h)][0] for h in hs], marker + "-", label=f"joint vs monolithic, {stop} s")
        ax0.loglog(hs, [acc[(stop, h)][1] for h in hs], marker + "--", label=f"joint vs converged, {stop} s")
    hs = np.array(STEPS)
    ax0.loglog(hs, 2e-5 * (hs / 4e-3) ** 2, "k:", label="h²")
    ax0.axhline(1e-5, color="grey", lw=0.8)
    ax0.set_xlabel("communication step h (s)")
    ax0.set_ylabel("max |slider error| (m)")
    ax0.set_title("C3's masses, joined at the pin")
    ax0.legend(fontsize=7)
    ax0.grid(True, which="both", alpha=0.3)
    for label in ["joint"] + [s[0] for s in study.SCHEMES]:
        pts = [(f, sweep[(f, label)]) for f in FACTORS if sweep[(f, label)] is not None]
        fails = [f for f in FACTORS if sweep[(f, label)] is None]
        style = "o-" if label == "joint" else ".--"
        line, = ax1.loglog(*zip(*pts), style, label=label) if pts else ax1.loglog([], [], style, label=label)
        ax1.plot(fails, [1.0] * len(fails), "x", color=line.get_color(), ms=9)
    ax1.set_xlabel("crank density / C3's")
    ax1.set_ylabel("max |slider error| (m), x = the run fails")
    ax1.set_title("h = 1 ms, 0.3 s: against the monolithic unit")
    ax1.legend(fontsize=7)
    ax1.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(OUT / "joint_study.png", dpi=110)
    if a.readme:
        fig.savefig(Path(__file__).parent / "joint_study.png", dpi=110)
    print((OUT / "joint_study.md").read_text())


if __name__ == "__main__":
    main()
