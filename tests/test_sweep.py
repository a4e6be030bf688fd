"""The Dask parameter sweep (examples/sweep.py, issue 6): a small C4 sweep on a LocalCluster of 2
worker processes gives exactly the results of the serial run. The engine is deterministic and each
task reuses one FMU instance through fmi2Reset, so a point's result must not depend on the worker
that ran it nor on the points its instance ran before: the serial reference runs every point on
one instance, in another order and grouping than the Dask tasks, and a fresh instance runs the
first point again. Equality is exact (bit for bit)."""

import importlib.util

import pytest

from fmu_util import ROOT

SCRIPT = ROOT / "examples" / "sweep.py"
STOP = 4.0
STEP = 1e-2


@pytest.fixture(scope="module")
def sweep():
    spec = importlib.util.spec_from_file_location("sweep", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def fmu_bytes(fmu_dir):
    path = fmu_dir / "spin_up_omega10.fmu"
    if not path.is_file():
        pytest.fail(f"{path} does not exist: run `make fmus` first")
    return path.read_bytes()


def test_two_dask_workers_equal_the_serial_run(sweep, fmu_bytes):
    e0 = sweep.E0
    points = [(8.0, e0), (2.0, e0), (5.0, 0.5 * e0), (10.0, 2.0 * e0)]
    client = sweep.local_client(2)
    try:
        assert len(client.scheduler_info()["workers"]) == 2
        progress = []
        parallel = sweep.sweep_dask(client, fmu_bytes, points, STOP, STEP, per_task=2, progress=progress.append)
    finally:
        sweep.close(client, fmu_bytes, client.cluster)
    assert len(progress) == 2 and "4/4 points" in progress[-1]

    try:
        serial = sweep.run_chunk(fmu_bytes, list(reversed(points)), STOP, STEP)[::-1]
        fresh = sweep.run_chunk(fmu_bytes, points[:1], STOP, STEP)
    finally:
        sweep.remove_unpacked(fmu_bytes)
    assert [(r["omega"], r["E"]) for r in parallel] == points
    assert parallel == serial
    assert parallel[0] == fresh[0]
    # the points differ from each other: equal results are not equal by accident
    peaks = [r["tip_deflection_max"] for r in parallel]
    assert len(set(peaks)) == len(peaks) and min(peaks) > 0.01


def test_the_script_writes_csv_and_plot_serially(sweep, fmu_dir, tmp_path, capsys):
    sweep.main(["--fmu", str(fmu_dir / "spin_up_omega10.fmu"), "-o", str(tmp_path), "--workers", "0",
                "--omega", "1", "3", "--e-factor", "1", "--stop", "1.0"])
    lines = (tmp_path / "sweep.csv").read_text().splitlines()
    assert lines[0].split(",") == sweep.COLUMNS
    assert len(lines) == 3
    assert (tmp_path / "sweep.png").stat().st_size > 10_000
    assert "2 points" in capsys.readouterr().out
