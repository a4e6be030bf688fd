"""`fmu-harness simulate` (the project's FMI master, fmu-harness/src/slave/mod.rs) agrees with fmpy's
`simulate_fmu`: same unit, same stop time and communication step, so both drive the engine through
the same calls and every output column must match to round-off (1e-12 relative to the value, or to
the column's largest magnitude for entries near zero)."""

import csv
import subprocess

import numpy as np
import pytest
from fmpy import simulate_fmu

SCENES = ["cantilever_free_vibration", "flexible_pendulum", "slider_crank"]
STOP = 0.5
STEP = 1e-3
RTOL = 1e-12


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], np.array([[float(x) for x in r] for r in rows[1:]])
    return {name: body[:, i] for i, name in enumerate(header)}


@pytest.mark.parametrize("scene", SCENES)
def test_simulate_equals_fmpy(scene, fmu_dir, harness, tmp_path):
    fmu = fmu_dir / f"{scene}.fmu"
    out = tmp_path / f"{scene}.csv"
    run = subprocess.run(
        [harness, "simulate", fmu, "--stop", str(STOP), "--step", str(STEP), "-o", out],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    ours = read_csv(out)
    columns = [c for c in ours if c != "time"]
    assert columns, "no output columns"

    ref = simulate_fmu(fmu, stop_time=STOP, output_interval=STEP, output=columns)
    assert len(ref) == len(ours["time"]) == round(STOP / STEP) + 1
    np.testing.assert_allclose(ours["time"], ref["time"], rtol=RTOL, atol=0)
    bad = []
    for c in columns:
        a, b = ours[c], np.asarray(ref[c], dtype=float)
        scale = max(np.max(np.abs(b)), np.finfo(float).tiny)
        err = np.abs(a - b)
        allowed = RTOL * np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-3 * scale)
        if np.any(err > allowed):
            i = int(np.argmax(err - allowed))
            bad.append(f"{c}: t = {ref['time'][i]}: ours {a[i]!r}, fmpy {b[i]!r}")
    assert not bad, "\n".join(bad)
