"""What the Python studies cost (issue 44, "How to measure"): `make bench-studies`.

1. The overhead of `Scene.simulate` against the same run through fmpy's `simulate_fmu` of the
   packaged unit (build/fmus/): CPU seconds of this process for each, interleaved, ROUNDS rounds,
   on C1-C4 and a 3D scene at their DefaultExperiment (the scene's step; fmpy told the same).
2. The speedup of a 32-variant sweep (examples/blade_droop: 8 hub speeds x 4 moduli, 6 s each)
   with 1 and 2 local processes, and on a Dask LocalCluster of 1 and 2 worker processes (one
   thread each): wall seconds, SWEEP_ROUNDS rounds each, interleaved.
3. What a task ships and returns: pickled bytes of a task and of its reduced and unreduced result.
4. The speedup of a Campbell diagram (the blade, 41 speeds, 6 modes) on 1 and 2 threads
   (`Scene.campbell(jobs=)`): wall seconds, SWEEP_ROUNDS rounds each, interleaved. (C2's accuracy
   study on 1 and 2 threads takes 3 min a run: docs/accuracy.md has it, `fmu-beam accuracy --jobs`.)

Writes build/bench/STUDIES.md and studies.json; prints the tables. Figures are min / median / max
over the rounds, with the load average before and after.
"""

import json
import os
import pickle
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "build" / "bench"
ROUNDS = int(os.environ.get("ROUNDS", 5))
SWEEP_ROUNDS = int(os.environ.get("SWEEP_ROUNDS", 3))
SCENES = ["cantilever_free_vibration", "flexible_pendulum", "slider_crank", "spin_up_omega10", "pendulum_3d_double"]
SPEEDS = [0.0, 4.0, 8.0, 12.0, 16.0, 20.0, 24.0, 28.0]
MODULI = [3.5e10, 5e10, 7e10, 14e10]


def spread(xs):
    return f"{min(xs):.3g} / {statistics.median(xs):.3g} / {max(xs):.3g}"


def load():
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def simulate_overhead():
    import logging

    import fmu_beam
    from fmpy import simulate_fmu

    logging.getLogger("fmu_beam").setLevel(logging.ERROR)
    rows = []
    for name in SCENES:
        scene = fmu_beam.Scene.load(ROOT / "scenes" / f"{name}.toml")
        step = scene.to_dict()["experiment"]["step_size"]
        fmu = str(ROOT / "build" / "fmus" / f"{name}.fmu")
        ours, theirs = [], []
        simulate_fmu(fmu, output_interval=step)  # warm: the library's first load, page cache
        for k in range(ROUNDS):
            for who in (("ours", "fmpy") if k % 2 == 0 else ("fmpy", "ours")):
                t = time.process_time()
                if who == "ours":
                    scene.simulate()
                    ours.append(time.process_time() - t)
                else:
                    simulate_fmu(fmu, output_interval=step, logger=lambda *a: None)
                    theirs.append(time.process_time() - t)
        ratios = [a / b for a, b in zip(ours, theirs)]
        rows.append({"scene": name, "ours_s": ours, "fmpy_s": theirs, "ratio": ratios})
        print(f"{name}: Scene.simulate {spread(ours)} s, fmpy {spread(theirs)} s, ratio {spread(ratios)}", flush=True)
    return rows


def blade_variants():
    return {"shaft.drive.omega": SPEEDS, "blade.E": MODULI}


def droop(df):
    return {"droop": -df["blade.tip.z"][df.index >= 5.0].mean()}


def sweep_speedup():
    import fmu_beam
    from distributed import Client, LocalCluster

    scene = fmu_beam.Scene.load(ROOT / "examples" / "blade_droop" / "blade.toml")
    walls = {"local 1": [], "local 2": [], "dask 1": [], "dask 2": []}
    reference = None
    clusters = {}
    try:
        for n in (1, 2):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                                   dashboard_address=None)
            clusters[n] = (cluster, Client(cluster))
        for k in range(SWEEP_ROUNDS):
            order = list(walls) if k % 2 == 0 else list(reversed(walls))
            for label in order:
                kind, n = label.split()
                n = int(n)
                t = time.perf_counter()
                if kind == "local":
                    df = fmu_beam.sweep(scene, blade_variants(), outputs=["blade.tip.z"], reduce=droop, jobs=n,
                                        progress=False)
                else:
                    df = fmu_beam.sweep(scene, blade_variants(), outputs=["blade.tip.z"], reduce=droop,
                                        client=clusters[n][1], progress=False)
                walls[label].append(time.perf_counter() - t)
                if reference is None:
                    reference = df
                assert df.equals(reference), f"{label}: the sweep's numbers differ from the first run's"
                print(f"round {k + 1}: {label}: {walls[label][-1]:.2f} s", flush=True)
    finally:
        for cluster, client in clusters.values():
            client.close()
            cluster.close()
    speed = {
        "local": statistics.median(walls["local 1"]) / statistics.median(walls["local 2"]),
        "dask": statistics.median(walls["dask 1"]) / statistics.median(walls["dask 2"]),
    }
    return walls, speed, reference


def payload():
    import fmu_beam
    from fmu_beam import _sweep

    scene = fmu_beam.Scene.load(ROOT / "examples" / "blade_droop" / "blade.toml")
    text = scene.to_toml()
    start = {"shaft.drive.omega": 20.0, "blade.E": 7e10}
    task = pickle.dumps((text, start, ["blade.tip.z"], {}, droop))
    reduced = pickle.dumps(_sweep._run_reduced(text, start, ["blade.tip.z"], {}, droop))
    series = pickle.dumps(_sweep._run(text, start, ["blade.tip.z"], {}))
    return {"task_bytes": len(task), "scene_text_bytes": len(text.encode()), "reduced_result_bytes": len(reduced),
            "series_result_bytes": len(series)}


def campbell_speedup():
    import fmu_beam

    scene = fmu_beam.Scene.load(ROOT / "examples" / "blade_droop" / "blade.toml")
    speeds = [0.5 * i for i in range(41)]
    walls = {1: [], 2: []}
    reference = None
    for k in range(SWEEP_ROUNDS):
        for jobs in ((1, 2) if k % 2 == 0 else (2, 1)):
            t = time.perf_counter()
            df = scene.campbell(speeds, count=6, jobs=jobs)
            walls[jobs].append(time.perf_counter() - t)
            if reference is None:
                reference = df
            assert df.equals(reference), f"jobs={jobs}: the diagram differs from the first run's"
            print(f"round {k + 1}: campbell jobs={jobs}: {walls[jobs][-1]:.2f} s", flush=True)
    return walls, statistics.median(walls[1]) / statistics.median(walls[2])


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    before = load()
    print(f"load before: {before}; {ROUNDS} rounds of simulate, {SWEEP_ROUNDS} of each sweep", flush=True)
    overhead = simulate_overhead()
    walls, speed, _ = sweep_speedup()
    sizes = payload()
    campbell_walls, campbell_speed = campbell_speedup()
    after = load()
    lines = [
        "# Python studies: what they cost",
        "",
        f"`make bench-studies` (bench/studies.py), {time.strftime('%Y-%m-%d %H:%M')}, {os.cpu_count()} cores, "
        f"load average before {before}, after {after}.",
        "",
        "## Scene.simulate against fmpy's simulate_fmu of the packaged unit",
        "",
        f"CPU seconds of this process, DefaultExperiment at the scene's step, {ROUNDS} rounds interleaved "
        "(min / median / max); ratio = Scene.simulate / fmpy.",
        "",
        "| scene | Scene.simulate (s) | fmpy (s) | ratio |",
        "|---|---|---|---|",
    ]
    for r in overhead:
        lines.append(f"| {r['scene']} | {spread(r['ours_s'])} | {spread(r['fmpy_s'])} | {spread(r['ratio'])} |")
    lines += [
        "",
        "## A 32-variant sweep on 1 and 2 workers",
        "",
        f"examples/blade_droop/blade.toml, 8 hub speeds x 4 moduli, 6 s of a 3D blade each; wall seconds, "
        f"{SWEEP_ROUNDS} rounds interleaved (min / median / max). Every run's numbers equal the first's.",
        "",
        "| where | 1 worker (s) | 2 workers (s) | speedup (medians) |",
        "|---|---|---|---|",
        f"| local processes (`jobs=`) | {spread(walls['local 1'])} | {spread(walls['local 2'])} | {speed['local']:.2f} |",
        f"| Dask LocalCluster, 1 thread a worker | {spread(walls['dask 1'])} | {spread(walls['dask 2'])} | "
        f"{speed['dask']:.2f} |",
        "",
        "## A Campbell diagram on 1 and 2 threads",
        "",
        f"examples/blade_droop/blade.toml, 41 speeds from 0 to 20 rad/s, 6 modes (`Scene.campbell(jobs=)`); wall "
        f"seconds, {SWEEP_ROUNDS} rounds interleaved (min / median / max). Every diagram equals the first.",
        "",
        "| 1 thread (s) | 2 threads (s) | speedup (medians) |",
        "|---|---|---|",
        f"| {spread(campbell_walls[1])} | {spread(campbell_walls[2])} | {campbell_speed:.2f} |",
        "",
        "## What a task ships",
        "",
        f"A task: {sizes['task_bytes']} bytes pickled (the scene's text {sizes['scene_text_bytes']} bytes, the "
        f"variant, the outputs, the reduction). Its result: {sizes['reduced_result_bytes']} bytes reduced, "
        f"{sizes['series_result_bytes']} bytes as the time series of one output (601 points).",
    ]
    text = "\n".join(lines) + "\n"
    (OUT / "STUDIES.md").write_text(text)
    (OUT / "studies.json").write_text(json.dumps({"overhead": overhead, "walls": walls, "speedup": speed,
                                                  "sizes": sizes, "campbell": {"walls": campbell_walls, "speedup": campbell_speed},
                                                  "load": [before, after]}, indent=1))
    print(text)


if __name__ == "__main__":
    sys.exit(main())
