"""The examples' READMEs say what their scripts measure (issue 31): `study.py` and `sweep.py`
write their figures into the README between markers, with the CSV they computed them from
beside them. Here the README's generated text must be what the script makes of its committed
CSV, and one row of each CSV is measured again with today's build (a second or two each): a
change of the engine that moves a figure fails here until the script is run again.

    .venv/bin/python examples/split_slider_crank/study.py   # table, study.csv, study.png
    .venv/bin/python examples/sweep.py                       # figures, sweep.csv, sweep.png
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
        assert now["slider"] == pytest.approx(row["slider"], rel=RELATIVE)
        assert now["tip"] == pytest.approx(row["tip"], rel=RELATIVE)
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
        assert now[key] == pytest.approx(row[key], rel=RELATIVE), key
    assert np.isclose(now["solver_steps"], row["solver_steps"])
