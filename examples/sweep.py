"""A parameter study of case C4 (the spin-up of an 8 m beam in 10 substructures,
scenes/spin_up_omega10.toml) on Dask: the peak tip deflection against the final hub speed Omega
for several Young's moduli E.

    .venv/bin/python examples/sweep.py                        # LocalCluster, 2 worker processes
    .venv/bin/python examples/sweep.py --workers 4
    .venv/bin/python examples/sweep.py --scheduler tcp://HOST:8786   # an existing dask.distributed cluster
    .venv/bin/python examples/sweep.py --workers 0            # serial, in this process (no Dask)
    .venv/bin/python examples/sweep.py --benchmark 5          # wall time of 1 and 2 workers, 5 runs each

Each Dask task gets a chunk of parameter points and the FMU's bytes (scattered once to every
worker, so workers need no shared file system); it unpacks the FMU once per worker process,
instantiates the unit once, and runs its points one after another on that instance, returning it
to the start with fmi2Reset (fmpy's FMU2Slave.reset()) and setting the fixed parameters
`hub.drive.omega` and `beam.E` before each initialization. Writes DIR/sweep.csv and DIR/sweep.png
(default DIR: build/examples/sweep) and prints progress as chunks complete.
"""

import argparse
import csv
import hashlib
import io
import logging
import os
import shutil
import statistics
import sys
import tempfile
import time
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FMU = ROOT / "build" / "fmus" / "spin_up_omega10.fmu"
OUT = ROOT / "build" / "examples" / "sweep"
E0 = 6.895e10
OMEGAS = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0]
E_FACTORS = [0.5, 1.0, 2.0]
LENGTH = 8.0
COLUMNS = ["omega", "E", "tip_deflection_max", "tip_deflection_end", "tip_radius_max", "hub_angle_end",
           "solver_steps"]
# The beam's tip may not move farther from the hub than this fraction of the length beyond it: a
# farther tip means a stretched beam, a model used beyond its (small-strain) validity.
STRETCH = 0.01

def unpacked_directory(fmu_bytes):
    """Where this process unpacks the FMU: named by content hash and process id, so that later
    tasks in the same worker process find it, whether Dask ships the task's function by
    reference or by value."""
    key = hashlib.sha256(fmu_bytes).hexdigest()[:16]
    return Path(tempfile.gettempdir()) / f"fmu_sweep_{key}_{os.getpid()}"


def unpack(fmu_bytes):
    """The directory where this process has unpacked the FMU, unzipped on first use."""
    directory = unpacked_directory(fmu_bytes)
    if not directory.is_dir():
        partial = Path(tempfile.mkdtemp(prefix=directory.name + "_", dir=directory.parent))
        with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as z:
            z.extractall(partial)
        os.replace(partial, directory)  # whole or not at all
    return str(directory)


def run_chunk(fmu_bytes, points, stop, step):
    """Runs each (omega, E) of `points` from t = 0 to `stop` with communication step `step` on one
    instance of the unit, reset between points; returns one result dict per point."""
    from fmpy import read_model_description
    from fmpy.fmi2 import FMU2Slave

    directory = unpack(fmu_bytes)
    md = read_model_description(directory)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=directory, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="sweep")
    fmu.instantiate()
    results = []
    try:
        for i, (omega, e) in enumerate(points):
            if i:
                fmu.reset()
            fmu.setReal([vr["hub.drive.omega"], vr["beam.E"]], [omega, e])
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            fmu.exitInitializationMode()
            tip = [vr["beam.tip.deflection"], vr["beam.tip.x"], vr["beam.tip.y"]]
            peak = radius = 0.0
            n = int(round(stop / step))
            for k in range(n):
                fmu.doStep(currentCommunicationPoint=k * step, communicationStepSize=step)
                deflection, x, y = fmu.getReal(tip)
                peak = max(peak, abs(deflection))
                radius = max(radius, (x * x + y * y) ** 0.5)
            end, angle = fmu.getReal([vr["beam.tip.deflection"], vr["hub.angle"]])
            (steps,) = fmu.getInteger([vr["solver.steps"]])
            results.append(dict(zip(COLUMNS, (omega, e, peak, end, radius, angle, steps))))
        fmu.terminate()
    finally:
        fmu.freeInstance()
        fmu.freeLibrary()
    return results


def remove_unpacked(fmu_bytes):
    """Removes this process's unpacked copy of the FMU (run on each worker before closing)."""
    shutil.rmtree(unpacked_directory(fmu_bytes), ignore_errors=True)


def close(client, fmu_bytes, cluster=None):
    """Removes the unpacked FMUs of the client's workers and of this process, closes the client
    and, if given, the cluster."""
    try:
        client.run(remove_unpacked, fmu_bytes)
    finally:
        remove_unpacked(fmu_bytes)
        client.close()
        if cluster is not None:
            cluster.close()


def grid(omegas=OMEGAS, e_factors=E_FACTORS):
    return [(omega, f * E0) for f in e_factors for omega in omegas]


def chunks(points, size):
    return [points[i:i + size] for i in range(0, len(points), size)]


def sweep_serial(fmu_bytes, points, stop, step, per_task):
    """The same chunks as the Dask run, one after another in this process."""
    return [r for chunk in chunks(points, per_task) for r in run_chunk(fmu_bytes, chunk, stop, step)]


def sweep_dask(client, fmu_bytes, points, stop, step, per_task, progress=print):
    """Submits one task per chunk to `client`; returns the results in the order of `points`."""
    from distributed import as_completed

    data = client.scatter(fmu_bytes, broadcast=True)
    parts = chunks(points, per_task)
    futures = {client.submit(run_chunk, data, part, stop, step, pure=False): i for i, part in enumerate(parts)}
    done = [None] * len(parts)
    start = time.perf_counter()
    for n, future in enumerate(as_completed(futures), 1):
        done[futures[future]] = future.result()
        progress(f"  {n}/{len(parts)} tasks, {sum(len(d) for d in done if d)}/{len(points)} points, "
                 f"{time.perf_counter() - start:.1f} s")
    return [r for part in done for r in part]


def local_client(workers):
    """A LocalCluster of `workers` single-threaded worker processes and its client."""
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                           silence_logs=logging.ERROR)
    return Client(cluster)


def write_csv(results, path):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in results:
            w.writerow({k: repr(v) for k, v in r.items()})


def plot(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for e in sorted({r["E"] for r in results}):
        rows = sorted((r for r in results if r["E"] == e), key=lambda r: r["omega"])
        ax.plot([r["omega"] for r in rows], [r["tip_deflection_max"] for r in rows], "o-",
                label=f"E = {e / 1e9:.4g} GPa")
    ax.set_xlabel("final hub speed Omega (rad/s), reached in 15 s")
    ax.set_ylabel("peak tip deflection (m)")
    ax.set_title("C4 spin-up, 10 substructures: peak tip deflection")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def benchmark(fmu_bytes, points, stop, step, per_task, runs):
    """Wall time of the whole sweep on warm LocalClusters of 1 and 2 workers (cluster start-up
    excluded), `runs` times each, interleaved; returns {workers: [seconds]}. Prints the 1-minute
    load average after each run: other processes on the machine slow the runs down."""
    clients = {w: local_client(w) for w in (1, 2)}
    times = {w: [] for w in clients}
    try:
        for c in clients.values():  # warm-up: unpack the FMU and import fmpy in every worker
            sweep_dask(c, fmu_bytes, points[:1], step, step, 1, progress=lambda _: None)
        for run in range(runs):
            for w, c in clients.items():
                start = time.perf_counter()
                sweep_dask(c, fmu_bytes, points, stop, step, per_task, progress=lambda _: None)
                times[w].append(time.perf_counter() - start)
                print(f"run {run + 1}/{runs}, {w} worker(s): {times[w][-1]:.2f} s "
                      f"(load average {os.getloadavg()[0]:.2f})", flush=True)
    finally:
        for c in clients.values():
            close(c, fmu_bytes, c.cluster)
    return times


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--fmu", type=Path, default=FMU)
    p.add_argument("-o", "--output", type=Path, default=OUT)
    p.add_argument("--scheduler", help="address of a dask.distributed scheduler (default: a LocalCluster)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes; 0: serial, no Dask")
    p.add_argument("--per-task", type=int, default=3, help="parameter points per task (one FMU instance)")
    p.add_argument("--omega", type=float, nargs="+", default=OMEGAS, help="final hub speeds (rad/s)")
    p.add_argument("--e-factor", type=float, nargs="+", default=E_FACTORS, help="E as multiples of 68.95 GPa")
    p.add_argument("--stop", type=float, default=20.0, help="simulated time per point (s)")
    p.add_argument("--step", type=float, default=1e-2, help="communication step (s)")
    p.add_argument("--benchmark", type=int, metavar="RUNS", help="time 1 and 2 local workers, RUNS runs each")
    a = p.parse_args(argv)
    if not a.fmu.is_file():
        sys.exit(f"{a.fmu} does not exist: run `make fmus` first")
    fmu_bytes = a.fmu.read_bytes()
    points = grid(a.omega, a.e_factor)

    if a.benchmark:
        times = benchmark(fmu_bytes, points, a.stop, a.step, a.per_task, a.benchmark)
        for w, ts in times.items():
            print(f"{w} worker(s): min {min(ts):.2f} s, median {statistics.median(ts):.2f} s, max {max(ts):.2f} s")
        speedups = [t1 / t2 for t1, t2 in zip(times[1], times[2])]
        print(f"speed-up of 2 workers over 1 (run by run): min {min(speedups):.2f}, "
              f"median {statistics.median(speedups):.2f}, max {max(speedups):.2f}")
        return

    start = time.perf_counter()
    print(f"{len(points)} points ({len(a.omega)} Omega x {len(a.e_factor)} E), {a.stop} s each, "
          f"{a.per_task} per task", flush=True)
    if a.workers == 0 and not a.scheduler:
        results = sweep_serial(fmu_bytes, points, a.stop, a.step, a.per_task)
        remove_unpacked(fmu_bytes)
    else:
        from distributed import Client

        client = Client(a.scheduler) if a.scheduler else local_client(a.workers)
        try:
            print(f"dask: {client}", flush=True)
            results = sweep_dask(client, fmu_bytes, points, a.stop, a.step, a.per_task,
                                 progress=lambda s: print(s, flush=True))
        finally:
            close(client, fmu_bytes, None if a.scheduler else client.cluster)
    for r in results:
        if r["tip_radius_max"] > (1 + STRETCH) * LENGTH:
            print(f"warning: Omega = {r['omega']}, E = {r['E']:.4g}: the tip reached "
                  f"{r['tip_radius_max']:.3f} m from the hub (beam length {LENGTH} m): outside the "
                  "model's validity, refine the substructures")
    a.output.mkdir(parents=True, exist_ok=True)
    write_csv(results, a.output / "sweep.csv")
    plot(results, a.output / "sweep.png")
    print(f"{len(results)} points in {time.perf_counter() - start:.1f} s; "
          f"wrote {a.output / 'sweep.csv'} and {a.output / 'sweep.png'}")


if __name__ == "__main__":
    main()
