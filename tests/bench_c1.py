"""Benchmark of case C1: CPU time per simulated second of the C1 FMU against the element count
and the solver setting (fixed step or error control, at each tolerance), median/min/max over
several runs (5; fewer once a configuration has used its CPU budget), timed around the
fmi2DoStep loop of an fmpy FMU2Slave (no result recording).

Element counts other than the scene's are temporary scenes derived from the C1 scene and
packaged with the harness under build/bench/. Writes build/bench/c1.csv. Run by `make bench`.
"""

import argparse
import csv
import re
import statistics
import sys
import time
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fmu_util import C1, ROOT, Logger, run_harness  # noqa: E402

ELEMENTS = [2, 5, 10, 20, 40]
TOLERANCES = [1e-4, 1e-6, 1e-8]
SETTINGS = [(False, tol) for tol in TOLERANCES] + [(True, tol) for tol in TOLERANCES]


def scene_with_elements(text, n):
    """The C1 scene text with n elements, under its own name (its own modelIdentifier)."""
    out, k1 = re.subn(r'(?m)^name = "cantilever_free_vibration"$', f'name = "c1_n{n}"', text)
    out, k2 = re.subn(r"(?m)^elements = \d+$", f"elements = {n}", out)
    if (k1, k2) != (1, 1):
        raise RuntimeError("the C1 scene no longer has the expected `name` and `elements` lines")
    return out


def package(harness, n, workdir):
    scene = workdir / "scenes" / f"c1_n{n}.toml"
    scene.parent.mkdir(parents=True, exist_ok=True)
    scene.write_text(scene_with_elements((ROOT / "scenes" / f"{C1}.toml").read_text(), n))
    fmu = workdir / "fmus" / f"c1_n{n}.fmu"
    r = run_harness(harness, "package", scene, "-o", fmu)
    if r.returncode != 0:
        raise RuntimeError(r.stderr)
    return fmu


def time_runs(fmu_path, settings, stop_time, runs, budget, workdir):
    """For each (adaptive, tolerance), as it completes: CPU seconds of each run and the final
    outputs."""
    md = read_model_description(fmu_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    h = float(md.defaultExperiment.stepSize)
    n_steps = round(stop_time / h)
    unzipdir = extract(fmu_path, unzipdir=workdir / "unzipped" / fmu_path.stem)
    logger = Logger()
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier)
    fmu.instantiate(callbacks=logger.callbacks)
    try:
        for adaptive, tol in settings:
            cpu = []
            while len(cpu) < runs and (not cpu or sum(cpu) < budget):
                fmu.reset()
                fmu.setBoolean([vr["solver.adaptive"]], [adaptive])
                fmu.setReal([vr["solver.tolerance"]], [tol])
                fmu.setupExperiment(startTime=0.0)
                fmu.enterInitializationMode()
                fmu.exitInitializationMode()
                t = 0.0
                c0 = time.process_time()
                for _ in range(n_steps):
                    fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
                    t += h
                cpu.append(time.process_time() - c0)
            stats = dict(
                zip(
                    ["steps", "newton_iterations", "rejected_steps"],
                    fmu.getInteger([vr["solver.steps"], vr["solver.newton_iterations"], vr["solver.rejected_steps"]]),
                )
            )
            tip = fmu.getReal([vr["beam.tip.deflection"]])[0]
            yield adaptive, tol, cpu, stats, tip
    finally:
        fmu.terminate()
        fmu.freeInstance()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--harness", type=Path, default=ROOT / "target" / "release" / "fmu-harness")
    ap.add_argument("--elements", type=int, nargs="+", default=ELEMENTS)
    ap.add_argument("--stop-time", type=float, default=0.2,
                    help="simulated seconds per run (default 0.2: the N = 40, 1e-8 runs take minutes)")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--budget", type=float, default=30.0,
                    help="CPU seconds per configuration after which no further run starts (at least one runs)")
    ap.add_argument("--out", type=Path, default=ROOT / "build" / "bench")
    args = ap.parse_args()

    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    header = (f"{'N':>3} {'solver':>8} {'tol':>7} {'runs':>4} {'median':>9} {'min':>9} {'max':>9}"
              f" {'steps':>7} {'newton':>8} {'rejected':>8} {'tip(T) m':>14}")
    print(f"C1, CPU seconds per simulated second, {args.runs} runs of {args.stop_time:g} s"
          f" (fewer past {args.budget:g} CPU s per configuration)")
    print(header)
    for n in args.elements:
        fmu = package(args.harness, n, args.out)
        for adaptive, tol, cpu, st, tip in time_runs(fmu, SETTINGS, args.stop_time, args.runs, args.budget, args.out):
            per = [c / args.stop_time for c in cpu]
            row = {
                "elements": n,
                "solver": "adaptive" if adaptive else "fixed",
                "tolerance": tol,
                "stop_time": args.stop_time,
                "runs": len(cpu),
                "cpu_per_sim_s_median": statistics.median(per),
                "cpu_per_sim_s_min": min(per),
                "cpu_per_sim_s_max": max(per),
                **st,
                "tip_deflection_end": tip,
            }
            rows.append(row)
            print(f"{n:>3} {row['solver']:>8} {tol:>7.0e} {len(cpu):>4} {row['cpu_per_sim_s_median']:>9.4f}"
                  f" {row['cpu_per_sim_s_min']:>9.4f} {row['cpu_per_sim_s_max']:>9.4f}"
                  f" {st['steps']:>7} {st['newton_iterations']:>8} {st['rejected_steps']:>8} {tip:>14.8e}",
                  flush=True)
    path = args.out / "c1.csv"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
