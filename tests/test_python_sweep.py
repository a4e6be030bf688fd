"""`fmu_beam.sweep` (issue 44 item 4): a design study of variants (start values and scene edits)
on the local cores and on a real Dask cluster gives, bit for bit, the numbers of the same sweep
run serially in this process; a worker killed in the middle loses no variant and changes no
number; a variant that fails has its reason in its row while the others complete; unknown names
and out-of-range values are refused before any run.

The Dask cluster is a scheduler and two workers started by the test as separate processes on
127.0.0.1 (`dask scheduler`, `dask worker`), and nothing else."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import fmu_beam
from fmu_util import ROOT

SCENE = ROOT / "scenes" / "spin_up_omega10.toml"
OUT = ["beam.tip.deflection", "hub.angle"]
E0 = 6.895e10


@pytest.fixture(scope="module")
def scene():
    return fmu_beam.Scene.load(SCENE)


def sixteen():
    """16 variants: the hub's final speed and the beam's modulus (start values)."""
    return {"hub.drive.omega": [2.0, 4.0, 6.0, 8.0], "beam.E": [0.5 * E0, E0, 1.5 * E0, 2.0 * E0]}


@pytest.fixture(scope="module")
def serial(scene):
    return fmu_beam.sweep(scene, sixteen(), outputs=OUT, reduce={"beam.tip.deflection": "absmax", "hub.angle": "last"},
                          jobs=1, progress=False)


def test_the_reduced_sweep_has_a_row_per_variant(serial):
    assert len(serial) == 16 and serial.index.name == "variant"
    assert list(serial.columns) == ["hub.drive.omega", "beam.E", "beam.tip.deflection", "hub.angle", "error"]
    assert serial["error"].isna().all()
    assert serial.attrs["units"]["beam.tip.deflection"] == "m"
    # the physics moves with the variants: a softer beam and a faster hub deflect more
    peak = serial.set_index(["hub.drive.omega", "beam.E"])["beam.tip.deflection"]
    assert peak[(8.0, 0.5 * E0)] > peak[(8.0, 2.0 * E0)] > 0
    assert peak[(8.0, E0)] > peak[(2.0, E0)]
    assert len(set(serial["beam.tip.deflection"])) == 16


def test_local_processes_equal_the_serial_run_bit_for_bit(scene, serial):
    parallel = fmu_beam.sweep(scene, sixteen(), outputs=OUT,
                              reduce={"beam.tip.deflection": "absmax", "hub.angle": "last"}, jobs=2, progress=False)
    pd.testing.assert_frame_equal(parallel, serial, check_exact=True)


def test_the_time_series_in_long_form(scene):
    variants = pd.DataFrame({"hub.drive.omega": [3.0, 9.0], "beam.substructures": [4, 8]})
    long = fmu_beam.sweep(scene, variants, outputs=OUT, stop_time=2.0, jobs=2, progress=False)
    assert long.index.names == ["variant", "time"]
    assert list(long.columns) == ["hub.drive.omega", "beam.substructures", *OUT, "error"]
    assert len(long) == 2 * 201
    # each variant's series is the scene's own run with that variant
    edited = fmu_beam.Scene.from_dict({**scene.to_dict(), "beam": [{**scene.to_dict()["beam"][0], "substructures": 8}]})
    one = edited.simulate(stop_time=2.0, outputs=OUT, start_values={"hub.drive.omega": 9.0})
    assert np.array_equal(long.loc[1][OUT].to_numpy(), one[OUT].to_numpy())


def test_a_failing_variant_has_its_reason_and_the_others_complete(scene):
    """A step budget of 5 steps a doStep cannot reach the 0.01 s communication points of the
    first variant (the solver's max_step is 1e-3 there); the others run as usual."""
    variants = [
        {"solver.max_step": 1e-4, "solver.step_budget": 5},
        {"solver.max_step": 1e-2, "solver.step_budget": 1_000_000},
        {"solver.max_step": 1e-2, "solver.step_budget": 1_000_000, "hub.drive.omega": 5.0},
    ]
    df = fmu_beam.sweep(scene, variants, outputs=OUT, reduce="last", stop_time=1.0, jobs=2, progress=False)
    assert df.attrs["failed"] == 1
    assert "budget" in df.loc[0, "error"]
    assert np.isnan(df.loc[0, "beam.tip.deflection"])
    assert df.loc[1:, "error"].isna().all()
    assert np.isfinite(df.loc[1:, "beam.tip.deflection"]).all()


@pytest.mark.parametrize(
    "variants, says",
    [
        ({"beam.nope": [1.0, 2.0]}, "'beam.nope' is neither a parameter"),
        ({"beam.E": [E0, -1.0]}, "variant 1"),
        ({"beam.substructures": [4, 0]}, "substructures"),
        ({"experiment.nothing.here": [1]}, "neither a parameter"),
        ({"beam.E": 3.0}, "a list of values"),
        ([{"beam.E": E0}, 5], "variants[1]"),
    ],
)
def test_unknown_names_and_out_of_range_values_are_refused_before_any_run(scene, variants, says, monkeypatch):
    ran = []
    monkeypatch.setattr(fmu_beam._sweep, "_run", lambda *a: ran.append(a))
    with pytest.raises(fmu_beam.Error) as caught:
        fmu_beam.sweep(scene, variants, outputs=OUT, reduce="last", jobs=1, progress=False)
    assert says in str(caught.value)
    assert not ran


def test_wrong_reductions_and_outputs_are_refused(scene):
    with pytest.raises(fmu_beam.Error, match="none of"):
        fmu_beam.sweep(scene, sixteen(), outputs=OUT, reduce="median-ish", progress=False)
    with pytest.raises(fmu_beam.Error, match="no output"):
        fmu_beam.sweep(scene, sixteen(), outputs=["no.such"], progress=False)


# -- a real Dask cluster of separate processes on 127.0.0.1 -------------------------------------


class Cluster:
    """`dask scheduler` and two `dask worker` processes (one thread each, no nanny: a killed
    worker stays dead), started here on 127.0.0.1 and stopped after the test."""

    def __init__(self, tmp: Path):
        self.file = tmp / "scheduler.json"
        dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
        self.logs = []
        self.scheduler = self._start(dask + ["--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                             "--scheduler-file", str(self.file)], tmp / "scheduler.log")
        deadline = time.time() + 60
        while not self.file.exists() and time.time() < deadline:
            time.sleep(0.1)
        assert self.file.exists(), (tmp / "scheduler.log").read_text()
        worker = [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file", str(self.file),
                  "--host", "127.0.0.1", "--nthreads", "1", "--no-nanny", "--no-dashboard"]
        self.workers = [self._start(worker + ["--name", f"w{k}"], tmp / f"worker{k}.log") for k in range(2)]
        self.address = json.loads(self.file.read_text())["address"]
        assert self.address.startswith("tcp://127.0.0.1:")

    def _start(self, argv, log):
        f = open(log, "w")
        self.logs.append(f)
        env = dict(os.environ, DASK_DISTRIBUTED__WORKER__DAEMON="False")
        return subprocess.Popen(argv, stdout=f, stderr=subprocess.STDOUT, env=env, cwd=ROOT)

    def stop(self):
        """The workers first, then the scheduler: a worker terminated with its scheduler often
        hangs in its event loop's shutdown until the wait below gives up (20 s each, 60 s of a
        pytest worker's time a run, measured 2026-12-06)."""
        for group in (self.workers, [self.scheduler]):
            for p in group:
                if p.poll() is None:
                    p.terminate()
            for p in group:
                try:
                    p.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()
        for f in self.logs:
            f.close()


@pytest.fixture
def cluster(tmp_path):
    c = Cluster(tmp_path)
    try:
        yield c
    finally:
        c.stop()


@pytest.fixture
def client(cluster):
    from distributed import Client

    with Client(cluster.address, timeout=60) as c:
        c.wait_for_workers(2, timeout=60)
        yield c


def test_a_dask_cluster_of_two_workers_equals_the_serial_run(scene, serial, client):
    workers = client.scheduler_info()["workers"]
    assert len(workers) == 2 and all(a.startswith("tcp://127.0.0.1:") for a in workers)
    on_dask = fmu_beam.sweep(scene, sixteen(), outputs=OUT,
                             reduce={"beam.tip.deflection": "absmax", "hub.angle": "last"}, client=client,
                             progress=False)
    pd.testing.assert_frame_equal(on_dask, serial, check_exact=True)
    # both workers ran some
    ran = client.run(lambda dask_worker: len(dask_worker.data) + dask_worker.state.executed_count)
    assert all(n > 0 for n in ran.values())


def test_a_worker_killed_in_the_middle_loses_no_variant(scene, serial, cluster, client):
    import threading

    box = {}

    def run():
        box["df"] = fmu_beam.sweep(scene, sixteen(), outputs=OUT,
                                   reduce={"beam.tip.deflection": "absmax", "hub.angle": "last"}, client=client,
                                   progress=False)

    thread = threading.Thread(target=run)
    thread.start()

    def finished(dask_scheduler):
        return sum(ts.state == "memory" for ts in dask_scheduler.tasks.values())

    deadline = time.time() + 120
    while client.run_on_scheduler(finished) < 3 and time.time() < deadline:
        time.sleep(0.05)
    done_before = client.run_on_scheduler(finished)
    assert 3 <= done_before < 16, "the sweep ended before the worker could be killed"
    victim = cluster.workers[0]
    os.kill(victim.pid, signal.SIGKILL)
    victim.wait(timeout=20)
    thread.join(timeout=300)
    assert not thread.is_alive()
    assert len(client.scheduler_info()["workers"]) == 1
    pd.testing.assert_frame_equal(box["df"], serial, check_exact=True)
