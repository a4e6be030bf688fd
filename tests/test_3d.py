"""3D scenes through fmpy, as a user runs them (issue 4): the C5 roll-up about either bending
axis closes its circle, a planar 3D scene runs with the planar element and agrees with the 3D
element, and the C6 pendulum and its rigid twin follow the exact rigid pendulum.

(fmpy's validator and a smoke run of every packaged FMU are in test_fmus_validate.py.)"""

import math
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from fmu_util import ROOT, run_harness

OUTPUTS_3D = [
    "beam.tip.x",
    "beam.tip.y",
    "beam.tip.z",
    "beam.tip.deflection_y",
    "beam.tip.deflection_z",
    "beam.tip.twist",
]


def fmu(fmu_dir, name):
    path = fmu_dir / f"{name}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} does not exist: run `make fmus` first")
    return path


def settled_tip(path):
    """Mean tip position over the held part of the roll-up (t >= 3 s, the moment is ramped over
    2 s), in units of L = 1 m."""
    r = simulate_fmu(str(path), output=OUTPUTS_3D)
    held = r["time"] >= 3.0 - 1e-9
    return np.array([r[f"beam.tip.{c}"][held].mean() for c in "xyz"]), r


def formulation(path):
    """The formulation line of the FMU's documentation (its resolved effects)."""
    with zipfile.ZipFile(path) as z:
        doc = z.read("documentation/index.html").decode()
    return next(line for line in doc.splitlines() if line.startswith("formulation"))


def test_3d_scenes_offer_the_3d_outputs(fmu_dir):
    for name in ["rollup_3d", "rollup_3d_z", "pendulum_3d"]:
        names = {v.name for v in read_model_description(fmu(fmu_dir, name)).modelVariables}
        assert set(OUTPUTS_3D) <= names, name
    rigid = {v.name for v in read_model_description(fmu(fmu_dir, "pendulum_3d_rigid")).modelVariables}
    assert "beam.tip.z" in rigid and "beam.tip.deflection_z" not in rigid


@pytest.mark.parametrize("name", ["rollup_3d", "rollup_3d_z"])
def test_c5_roll_up_returns_the_tip_to_the_root(fmu_dir, name):
    """C5: M = 2 pi E I / L rolls the beam into a circle; the tip ends at the root (within
    1 % of L, the issue's bound; the Rust test spatial_system.rs also checks the 2 pi turn)."""
    tip, r = settled_tip(fmu(fmu_dir, name))
    print(f"{name}: settled tip at {tip} m, {100 * np.linalg.norm(tip):.3f} % of L from the root")
    assert np.linalg.norm(tip) < 0.01
    # on the way the tip left the beam's line: it went round, not back along the axis
    if name == "rollup_3d":  # about y: the beam curls in the x-z plane
        assert np.abs(r["beam.tip.z"]).max() > 0.3
        assert np.abs(r["beam.tip.y"]).max() == 0.0
    else:  # about z: in the x-y plane
        assert np.abs(r["beam.tip.y"]).max() > 0.3
        assert np.abs(r["beam.tip.z"]).max() == 0.0


def test_a_planar_3d_scene_runs_with_the_planar_element_and_agrees_with_the_3d_one(
    fmu_dir, harness, tmp_path
):
    """rollup_3d_z moves in the x-y plane: formulation "auto" picks the planar element. The
    same scene forced to the 3D element (formulation = "spatial") gives the same tip history
    within 1e-6 of L (same substructures, same fixed step; the rotations are parametrized
    differently: an angle against a quaternion). Both on the paper's 10 substructures rather
    than the shipped 64: the elements are compared, not the mesh, and the 3D one at 5e-4 s
    costs 6 times less so."""
    assert "planar" in formulation(fmu(fmu_dir, "rollup_3d_z"))
    text = (ROOT / "scenes" / "rollup_3d_z.toml").read_text()
    assert 'name = "rollup_3d_z"' in text and "dimensions = 3\n" in text
    assert "substructures = 64\n" in text
    text = text.replace("substructures = 64\n", "substructures = 10\n")
    paths = {}
    for element, extra in [("planar", ""), ("spatial", 'formulation = "spatial"\n')]:
        named = text.replace('name = "rollup_3d_z"', f'name = "rollup_3d_z_{element}"')
        named = named.replace("dimensions = 3\n", f"dimensions = 3\n{extra}")
        scene = tmp_path / f"rollup_3d_z_{element}.toml"
        scene.write_text(named)
        paths[element] = tmp_path / f"rollup_3d_z_{element}.fmu"
        r = run_harness(harness, "package", scene, "--output", paths[element])
        assert r.returncode == 0, r.stderr
        assert element in formulation(paths[element])
    planar, spatial = paths["planar"], paths["spatial"]
    # Both at a fixed step of 5e-4 s with Newton converged to 1e-10: 6.7e-8 m apart, and no
    # step cut short. (At the paper scene's settings, 1e-3 s and Newton to 1e-8, they differ by
    # 2.6e-7 m, and by 2.5e-7 m with Newton to 1e-10: there the two time errors differ.) A step
    # cut short changes the 3D run's time grid: before Newton learned the noise of the roll-up's
    # difference gradients, eight were, and the two ran 2.4e-6 m apart. The time error itself is
    # far larger: the tip at 1 s moves by 8e-4 m from a step of 1e-3 s to 5e-4 s, in both
    # formulations alike.
    fine = {"solver.max_step": 5e-4, "solver.tolerance": 1e-10}
    outputs = OUTPUTS_3D + ["solver.split_steps"]
    a = simulate_fmu(str(planar), output=outputs, start_values=fine)
    b = simulate_fmu(str(spatial), output=outputs, start_values=fine)
    assert a["solver.split_steps"][-1] == 0 and b["solver.split_steps"][-1] == 0
    for name in OUTPUTS_3D:
        diff = np.abs(a[name] - b[name]).max()
        print(f"{name}: planar vs 3D element, max difference {diff:.2e} m (L = 1 m)")
        assert diff < 1e-6, name


def exact_rigid_pendulum(t_end, rho=7800.0, area=1.257e-3, length=0.2, g=9.81, h=1e-4):
    """Hinge angle and rate at t_end of the rigid bar released horizontal: J th'' = m g c cos th
    with J = m L^2 / 3 (Euler-Bernoulli elements carry no rotary inertia of bending, so the
    rigid twin has none either), by classical Runge-Kutta (h = 1e-4 s: error far below 1e-9)."""
    m = rho * area * length
    c = length / 2
    k = m * g * c / (m * length**2 / 3)
    th, w = 0.0, 0.0
    for _ in range(round(t_end / h)):
        a1, b1 = w, k * math.cos(th)
        a2, b2 = w + h / 2 * b1, k * math.cos(th + h / 2 * a1)
        a3, b3 = w + h / 2 * b2, k * math.cos(th + h / 2 * a2)
        a4, b4 = w + h * b3, k * math.cos(th + h * a3)
        th += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        w += h / 6 * (b1 + 2 * b2 + 2 * b3 + b4)
    return th, w


def test_c6_pendulum_and_its_rigid_twin_follow_the_rigid_pendulum(fmu_dir):
    """C6 at the scenes' tolerance (1e-7): the rigid twin's hinge angle at 1 s is within 1e-4 rad
    of the exact rigid pendulum (measured 7.2e-5 rad: the twin's time error, which shrinks only
    slowly with the tolerance). The flexible pendulum stays within 1e-4 rad of its twin (its lag
    behind the exact rigid pendulum is 5.7e-8 s, 5.4e-7 rad, see spatial_system.rs), bends in
    its plane of motion only (deflection_y and twist stay 0) and by a small amount."""
    exact, rate = exact_rigid_pendulum(1.0)
    outs = ["hinge.angle", "hinge.speed", "beam.tip.x", "beam.tip.z"]
    rigid = simulate_fmu(str(fmu(fmu_dir, "pendulum_3d_rigid")), output=outs)
    flex = simulate_fmu(
        str(fmu(fmu_dir, "pendulum_3d")),
        output=outs + ["beam.tip.deflection_y", "beam.tip.deflection_z", "beam.tip.twist"],
    )
    print(
        f"hinge angle at 1 s: exact {exact:.7f}, rigid twin {rigid['hinge.angle'][-1]:.7f}, "
        f"flexible {flex['hinge.angle'][-1]:.7f} rad"
    )
    assert rigid["hinge.angle"][-1] == pytest.approx(exact, abs=1e-4)
    assert rigid["hinge.speed"][-1] == pytest.approx(rate, rel=1e-4)
    assert np.abs(flex["hinge.angle"] - rigid["hinge.angle"]).max() < 1e-4
    # the tip stays on the circle of radius L about the hinge (the beam is nearly rigid)
    radius = np.hypot(flex["beam.tip.x"], flex["beam.tip.z"])
    assert np.abs(radius - 0.2).max() < 1e-6
    assert np.abs(flex["beam.tip.deflection_y"]).max() == 0.0
    assert np.abs(flex["beam.tip.twist"]).max() == 0.0
    sag = np.abs(flex["beam.tip.deflection_z"]).max()
    assert 0.0 < sag < 1e-6, sag
