"""The examples' READMEs say what their scripts measure (issue 31): `study.py`, `joint_study.py`,
`sweep.py`, `hub_sweep.py` and `arm_pid.py --table` write their figures into the README between
markers, with the CSV they computed them from beside them. Here the README's generated text must
be what the script makes of its committed CSV, and one row of each CSV is measured again with
today's build (a second or two each): a change of the engine that moves a figure fails here until
the script is run again.

    .venv/bin/python examples/split_slider_crank/study.py               # table, study.csv, study.png
    .venv/bin/python examples/split_slider_crank/joint_study.py --readme  # tables, joint_study.{csv,png}
    .venv/bin/python examples/sweep.py                                   # figures, sweep.csv, sweep.png
    .venv/bin/python examples/hinged_blade/hub_sweep.py --readme         # tables, hub_sweep.{csv,png}
    .venv/bin/python examples/flexible_arm_pid/arm_pid.py --table        # table, arm_pid_table.csv
"""

import importlib.util
import sys

import numpy as np
import pytest

from fmu_util import ROOT

EXAMPLES = ROOT / "examples"
# The engine is deterministic, so a row measured again equals the CSV's; the tolerance leaves
# room for another platform's last bits, far below the 2-3 digits the READMEs print.
RELATIVE = 1e-6


def load(path):
    sys.path.insert(0, str(path.parent))
    try:
        spec = importlib.util.spec_from_file_location(path.stem, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    finally:
        sys.path.remove(str(path.parent))


@pytest.fixture(scope="module")
def study():
    return load(EXAMPLES / "split_slider_crank" / "study.py")


@pytest.fixture(scope="module")
def sweep():
    return load(EXAMPLES / "sweep.py")


@pytest.fixture(scope="module")
def joint_study():
    return load(EXAMPLES / "split_slider_crank" / "joint_study.py")


@pytest.fixture(scope="module")
def hub_sweep():
    return load(EXAMPLES / "hinged_blade" / "hub_sweep.py")


@pytest.fixture(scope="module")
def arm_pid():
    return load(EXAMPLES / "flexible_arm_pid" / "arm_pid.py")


def test_the_split_study_table_is_the_scripts(study):
    rows = study.read_rows(study.HERE / "study.csv")
    assert len(rows) == 40
    assert study.readme_table(study.README.read_text()) == study.table(rows)


@pytest.mark.parametrize(
    "crank, scheme, step",
    [("20× denser crank", "Gauss-Seidel, quadratic", 1e-3), ("C3 (ρ = 2770)", "Jacobi, held", 1e-3)],
)
def test_a_row_of_the_split_study_measured_again(study, fmu_dir, crank, scheme, step):
    rows = study.read_rows(study.HERE / "study.csv")
    (row,) = [r for r in rows if (r["crank"], r["scheme"], r["step"]) == (crank, scheme, step)]
    rho = dict(study.DENSITIES)[crank]
    (alg, ext) = next((a, e) for label, a, e in study.SCHEMES if label == scheme)
    ref = study.reference(step, study.DEFAULT_STOP, rho)
    now = study.errors(step, study.DEFAULT_STOP, alg, ext, rho, ref)
    assert now["ok"] == row["ok"], now["message"]
    if row["ok"]:
        assert now["slider"] == pytest.approx(row["slider"], rel=RELATIVE, abs=0)
        assert now["tip"] == pytest.approx(row["tip"], rel=RELATIVE, abs=0)
    else:
        assert now["failed_at"] == pytest.approx(row["failed_at"], rel=RELATIVE)


def test_the_sweep_figures_are_the_scripts(sweep):
    results = sweep.read_csv(sweep.HERE / "sweep.csv")
    assert len(results) == len(sweep.OMEGAS) * len(sweep.E_FACTORS)
    assert sweep.readme_figures(sweep.README.read_text()) == sweep.figures(results)


def test_the_sweep_s_c4_point_measured_again(sweep, fmu_dir):
    results = sweep.read_csv(sweep.HERE / "sweep.csv")
    (row,) = [r for r in results if r["omega"] == 10.0 and r["E"] == sweep.E0]
    fmu_bytes = (fmu_dir / "spin_up_omega10.fmu").read_bytes()
    try:
        (now,) = sweep.run_chunk(fmu_bytes, [(10.0, sweep.E0)], sweep.DEFAULT_STOP, sweep.DEFAULT_STEP)
    finally:
        sweep.remove_unpacked(fmu_bytes)
    for key in ("tip_deflection_max", "tip_deflection_end", "tip_radius_max"):
        assert now[key] == pytest.approx(row[key], rel=RELATIVE, abs=0), key
    assert np.isclose(now["solver_steps"], row["solver_steps"])


def test_the_joint_study_tables_are_the_scripts(joint_study):
    rows = joint_study.read_rows(joint_study.HERE / "joint_study.csv")
    assert len(rows) == 2 * len(joint_study.STEPS) + len(joint_study.FACTORS) * 7
    assert joint_study.readme_blocks(joint_study.README.read_text()) == joint_study.generated(rows)


def test_a_row_of_the_joint_study_measured_again(joint_study, fmu_dir):
    """The coupled run at h = 4 ms over 0.3 s against the monolithic unit (not the converged
    reference: that is 24 000 steps of the monolithic unit)."""
    rows = joint_study.read_rows(joint_study.HERE / "joint_study.csv")
    (row,) = [r for r in rows if r["part"] == "accuracy" and (r["stop"], r["step"]) == (0.3, 4e-3)]
    now = joint_study.accuracy_row(0.3, 4e-3, None)
    assert now["ok"] and row["ok"]
    for key in ("error_mono", "iterations", "restores", "unit_steps", "refused"):
        assert now[key] == pytest.approx(row[key], rel=RELATIVE, abs=0), key


def test_the_hub_sweep_tables_are_the_scripts(hub_sweep):
    rows = hub_sweep.read_rows(hub_sweep.HERE / "hub_sweep.csv")
    assert len(rows) == len(hub_sweep.FACTORS) + len(hub_sweep.STEPS)
    assert hub_sweep.readme_blocks(hub_sweep.README.read_text()) == hub_sweep.generated(rows)


def test_a_row_of_the_hub_sweep_measured_again(hub_sweep, fmu_dir):
    """The scene's hub at h = 4 ms: the joint coupling against the monolithic unit."""
    rows = hub_sweep.read_rows(hub_sweep.HERE / "hub_sweep.csv")
    (row,) = [r for r in rows if r["part"] == "step" and r["step"] == 4e-3]
    now = hub_sweep.joint_row("step", 1.0, 4e-3)
    assert now["ok"] and row["ok"]
    for key in ("angle_error", "tip_error", "iterations", "unit_steps", "refused"):
        assert now[key] == pytest.approx(row[key], rel=RELATIVE, abs=0), key


def test_the_arm_pid_table_is_the_scripts(arm_pid):
    rows = arm_pid.read_table()
    assert [r["case"] for r in rows] == [c[0] for c in arm_pid.CASES]
    assert arm_pid.readme_table(arm_pid.README.read_text()) == arm_pid.table(rows)


def test_the_arm_pid_default_row_measured_again(arm_pid, fmu_dir):
    (row,) = [r for r in arm_pid.read_table() if r["case"] == arm_pid.CASES[0][0]]
    now = arm_pid.case_figures(arm_pid.CASES[0], fmu_dir / "flexible_arm_hub.fmu")
    for key in arm_pid.TABLE_FIELDS[1:]:
        assert now[key] == pytest.approx(row[key], rel=RELATIVE, abs=0), key
