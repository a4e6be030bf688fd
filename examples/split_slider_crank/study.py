"""Communication step against error and stability of the split slider-crank, for Jacobi,
Gauss-Seidel and extrapolated inputs, through `fmu-harness cosim`; the reference is the monolithic
slider_crank FMU (fmpy) with the same crank density. Writes build/split/study.{csv,md,png}.

    python study.py [--stop 0.3] [--steps 4e-3,2e-3,1e-3,5e-4]
"""

import argparse
import csv
import re
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from fmpy import simulate_fmu

ROOT = Path(__file__).resolve().parents[2]
HARNESS = ROOT / "target" / "release" / "fmu-harness"
FMUS = ROOT / "build" / "fmus"
OUT = ROOT / "build" / "split"

# (label, algorithm, extrapolation of the pin position; the pin force is always held)
SCHEMES = [
    ("Jacobi, held", "jacobi", "none"),
    ("Gauss-Seidel, held", "gauss-seidel", "none"),
    ("Jacobi, quadratic", "jacobi", "quadratic"),
    ("Gauss-Seidel, linear", "gauss-seidel", "linear"),
    ("Gauss-Seidel, quadratic", "gauss-seidel", "quadratic"),
]
DENSITIES = [("C3 crank (rho 2770)", 2770.0), ("20x denser crank", 55400.0)]


def system_text(step, stop, algorithm, extrapolation, rho):
    fmus = FMUS.resolve()
    return f"""stop_time = {stop!r}
step = {{ size = {step!r} }}
algorithm = "{algorithm}"
order = ["crank", "rod"]
extrapolation = "{extrapolation}"
outputs = ["crank.crank.tip.y", "rod.slider.position"]
connections = [
  "crank.crank.tip.x -> rod.pin_x.drive.position",
  "crank.crank.tip.y -> rod.pin_y.drive.position",
  {{ from = "rod.pin_x.force", to = "crank.pin.fx", factor = -1.0, extrapolation = "none" }},
  {{ from = "rod.pin_y.force", to = "crank.pin.fy", factor = -1.0, extrapolation = "none" }},
]
[[unit]]
name = "crank"
fmu = "{fmus / 'slider_crank_split_crank.fmu'}"
start = {{ "crank.rho" = {rho!r} }}
[[unit]]
name = "rod"
fmu = "{fmus / 'slider_crank_split_rod.fmu'}"
"""


def cosim(step, stop, algorithm, extrapolation, rho):
    """(time, tip y, slider) arrays, or the failure time and message."""
    with tempfile.TemporaryDirectory() as d:
        sysfile, out = Path(d) / "system.toml", Path(d) / "out.csv"
        sysfile.write_text(system_text(step, stop, algorithm, extrapolation, rho))
        run = subprocess.run([HARNESS, "cosim", sysfile, "-o", out], capture_output=True, text=True)
        if run.returncode != 0:
            m = re.search(r"at t = ([0-9.eE+-]+)", run.stderr)
            return None, (float(m.group(1)) if m else float("nan")), run.stderr.strip()
        data = np.loadtxt(out, delimiter=",", skiprows=1)
        return data, None, None


def reference(step, stop, rho):
    r = simulate_fmu(FMUS / "slider_crank.fmu", stop_time=stop, output_interval=step,
                     output=["crank.tip.y", "slider.position"], start_values={"crank.rho": rho})
    return np.c_[r["time"], r["crank.tip.y"], r["slider.position"]]


def errors(step, stop, algorithm, extrapolation, rho, ref):
    data, failed_at, message = cosim(step, stop, algorithm, extrapolation, rho)
    if data is None:
        return dict(ok=False, failed_at=failed_at, tip=np.nan, slider=np.nan, message=message)
    diff = np.abs(data[:, 1:] - ref[:, 1:])
    if not np.all(np.isfinite(diff)):
        return dict(ok=False, failed_at=np.nan, tip=np.nan, slider=np.nan, message="non-finite")
    return dict(ok=True, failed_at=None, tip=diff[:, 0].max(), slider=diff[:, 1].max(), message="")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stop", type=float, default=0.3)
    ap.add_argument("--steps", default="4e-3,2e-3,1e-3,5e-4")
    a = ap.parse_args()
    steps = [float(s) for s in a.steps.split(",")]
    OUT.mkdir(parents=True, exist_ok=True)
    rows = []
    for dlabel, rho in DENSITIES:
        for h in steps:
            ref = reference(h, a.stop, rho)
            for label, alg, ext in SCHEMES:
                e = errors(h, a.stop, alg, ext, rho, ref)
                rows.append(dict(crank=dlabel, rho=rho, scheme=label, step=h, **e))
                state = (f"tip {e['tip']:.3e} m, slider {e['slider']:.3e} m" if e["ok"]
                         else f"FAILED at t = {e['failed_at']}")
                print(f"{dlabel:>20} | {label:>24} | h = {h:.0e} | {state}", flush=True)
    with open(OUT / "study.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["crank", "rho", "scheme", "step", "ok", "failed_at",
                                          "tip", "slider", "message"])
        w.writeheader()
        w.writerows(rows)
    lines = ["| crank | scheme | " + " | ".join(f"h = {h:g} s" for h in steps) + " |",
             "|---|---|" + "---|" * len(steps)]
    for dlabel, _ in DENSITIES:
        for label, _, _ in SCHEMES:
            cells = []
            for h in steps:
                r = next(r for r in rows if r["crank"] == dlabel and r["scheme"] == label
                         and r["step"] == h)
                cells.append(f"{r['slider']:.2e}" if r["ok"] else f"fails at t = {r['failed_at']:g}")
            lines.append(f"| {dlabel} | {label} | " + " | ".join(cells) + " |")
    (OUT / "study.md").write_text("Max |slider position error| (m) against the monolithic unit over "
                                  f"{a.stop} s\n\n" + "\n".join(lines) + "\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for ax, (dlabel, _) in zip(axes, DENSITIES):
        for label, _, _ in SCHEMES:
            pts = [(r["step"], r["slider"]) for r in rows
                   if r["crank"] == dlabel and r["scheme"] == label and r["ok"]]
            fails = [r["step"] for r in rows
                     if r["crank"] == dlabel and r["scheme"] == label and not r["ok"]]
            line, = ax.loglog(*zip(*pts), "o-", label=label) if pts else ax.loglog([], [], label=label)
            for h in fails:
                ax.plot([h], [1.0], "x", color=line.get_color(), ms=9)
        ax.set_title(dlabel)
        ax.set_xlabel("communication step h (s)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max |slider error| (m), x = run failed")
    axes[1].legend(fontsize=8)
    fig.suptitle(f"Split slider-crank against the monolithic unit, {a.stop} s")
    fig.tight_layout()
    fig.savefig(OUT / "study.png", dpi=110)
    print(f"wrote {OUT / 'study.csv'}, {OUT / 'study.md'}, {OUT / 'study.png'}")


if __name__ == "__main__":
    main()
