"""Scene.modes and Scene.campbell in process (issue 44): the frequencies, damping ratios and shapes
as numpy arrays with their coordinates named, the old list of frequencies still there, the
Campbell diagram as a DataFrame equal to `fmu-beam modes --campbell`'s CSV and the same on one or
two threads; numpy and pandas imported only when asked for."""

import json
import math
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import fmu_beam

ROOT = Path(__file__).resolve().parent.parent
L, RHO, E = 2.0, 2700.0, 72e9


def beam(joint: str, extra: str = "", dimensions: int = 2, section: str = "a = 0.01, b = 0.01") -> fmu_beam.Scene:
    """The C1 beam (L = 2 m, aluminium), 16 elements, along x from the origin, with `joint` at its root."""
    three = "dimensions = 3\n" if dimensions == 3 else ""
    g = ", G = 27e9" if dimensions == 3 else ""
    return fmu_beam.Scene.from_toml(
        f'name = "b"\n{three}[[beam]]\nname = "beam"\nlength = {L}\nelements = 16\n{extra}\n'
        f'material = {{ rho = {RHO}, E = {E}{g} }}\nsection = {{ shape = "rectangle", {section} }}\n{joint}')


CLAMP = '[[joint]]\nname = "clamp"\ntype = "weld"\nframes = ["world", "beam.a"]'
PIN = '[[joint]]\nname = "pin"\ntype = "revolute"\nframes = ["world", "beam.a"]'
HUB = PIN.replace('"pin"', '"hub"') + '\ndrive = { kind = "motion", law = "spin_up", omega = 8.0, ramp_time = 10.0 }'


def clamped_free(beta_l: float, h: float = 0.01) -> float:
    return beta_l ** 2 / (2 * math.pi * L * L) * math.sqrt(E * h * h / 12 / RHO)


def test_modes_is_still_the_list_of_frequencies():
    """What Scene.modes returned before (a list of floats) still works: the README's quickstart
    formats them, test_wheel dumps them as JSON, and a list compares equal."""
    pendulum = fmu_beam.Scene.load(ROOT / "scenes" / "flexible_pendulum.toml")
    m = pendulum.modes(count=2)
    assert isinstance(m, list) and isinstance(m, fmu_beam.Modes) and len(m) == 2
    assert ", ".join(f"{f:.2f} Hz" for f in m) == "16.93 Hz, 54.87 Hz"  # the README's line
    assert json.loads(json.dumps(m)) == m == list(m.frequencies)
    assert all(type(f) is float for f in m) and m[0] == m.frequencies[0]
    assert pendulum.modes(count=5)[:2] == m
    assert len(pendulum.modes()) > 5
    # a result travels (to a Dask worker and back) with its arrays
    back = pickle.loads(pickle.dumps(m))
    assert back == m and np.array_equal(back.shapes, m.shapes) and back.coordinates == m.coordinates
    none = pendulum.modes(count=0)
    assert none == [] and none.shapes.shape == (len(m.coordinates), 0)


def test_import_needs_neither_numpy_nor_pandas():
    code = ("import sys, fmu_beam; s = fmu_beam.Scene.load(sys.argv[1]); print(len(s.to_toml()) > 0, "
            "'numpy' in sys.modules, 'pandas' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code, str(ROOT / "scenes" / "cantilever_free_vibration.toml")],
                          capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["True", "False", "False"]


def test_clamped_beam_frequencies_shapes_and_coordinates():
    """Clamped-free: the closed forms within 1e-7, 5e-6, 4e-5 (16 elements), ratio 0 without damping, the
    shapes (coordinates x modes, largest entry 1) the beam's bending at its nodes."""
    m = fmu_beam.Scene.modes(beam(CLAMP), count=3)
    exact = [clamped_free(b) for b in (1.875_104_1, 4.694_091_1, 7.854_757_4)]
    assert np.allclose(m.frequencies, exact, rtol=1e-4) and m[0] == pytest.approx(exact[0], rel=1e-6)
    assert m.frequencies.dtype == np.float64 and m.frequencies.shape == (3,)
    assert np.array_equal(m.damped_frequencies, m.frequencies) and not m.damping_ratios.any()
    assert m.coordinates[:3] == ["beam.shape.x[1]", "beam.shape.y[1]", "beam.shape.phi[1]"]
    assert m.shapes.shape == (17 * 3, 3) and len(m.coordinates) == 17 * 3
    assert np.allclose(np.abs(m.shapes).max(axis=0), 1.0)
    tip = m.shape(0)["beam.shape.y[17]"]
    assert tip == 1.0 and m.shape(0)["beam.shape.y[1]"] == 0.0
    # mode 2 has its node at x = 0.7834 L: its y changes sign between nodes 13 and 14
    y2 = m.shapes[[m.coordinates.index(f"beam.shape.y[{i}]") for i in range(1, 18)], 1]
    assert np.sum(np.diff(np.sign(y2[1:])) != 0) == 1 and y2[12] * y2[13] < 0
    assert (m.speed, m.hub, m.locked, m.rigid_body_modes, m.non_oscillating) == (0.0, None, [], 0, 0)
    frame = m.to_frame()
    assert list(frame.index) == [1, 2, 3] and frame.attrs["units"]["frequency"] == "Hz"


def test_damping_ratios_and_overdamped_roots_left_out():
    """A 3D beam on the spatial element with beta = 4e-3 s (issue 44's defect 1): each mode's
    ratio is beta*omega/2, the overdamped ones are counted as non-oscillating, never listed."""
    beta = 4e-3
    scene = beam(CLAMP, f"rayleigh = {{ alpha = 0.0, beta = {beta} }}", dimensions=3)
    scene = fmu_beam.Scene.from_toml(scene.to_toml().replace('formulation = "auto"', 'formulation = "spatial"'))
    m = scene.modes()
    assert m.damped and m.non_oscillating > 0
    omega = 2 * math.pi * m.frequencies
    assert np.allclose(m.damping_ratios, beta * omega / 2, rtol=1e-6)
    assert np.allclose(m.damped_frequencies, m.frequencies * np.sqrt(1 - m.damping_ratios ** 2), rtol=1e-6)
    assert m.frequencies[0] == pytest.approx(clamped_free(1.875_104_1), rel=1e-5)
    assert (m.damping_ratios < 1).all() and len(m) + m.non_oscillating == len(m.undamped_frequencies)


def test_locked_joints_and_speed():
    pinned = beam(PIN)
    free, locked, every = pinned.modes(count=3), pinned.modes(count=3, lock="pin"), pinned.modes(count=3, lock=True)
    assert free.rigid_body_modes == 1 and locked.rigid_body_modes == 0 and locked.locked == ["pin"]
    assert locked == every == pinned.modes(count=3, lock=["pin"])
    assert locked[0] == pytest.approx(clamped_free(1.875_104_1), rel=1e-5)
    spun = beam(HUB, "geometric_stiffening = true").modes(count=2, speed=6.0)
    assert spun.speed == 6.0 and spun.hub == "hub" and spun.driven == ["hub"]
    # in-plane: omega^2 = omega0^2 + (K - 1) Omega^2, K = 1.1941 for 16 elements
    w0 = 2 * math.pi * clamped_free(1.875_104_1)
    assert 2 * math.pi * spun[0] == pytest.approx(math.sqrt(w0 ** 2 + 0.1941 * 36), rel=1e-3)
    with pytest.raises(fmu_beam.Error, match="no joint named 'elbow'"):
        pinned.modes(lock="elbow")
    with pytest.raises(TypeError, match="lock"):
        pinned.modes(lock=3)
    with pytest.raises(fmu_beam.Error, match="not a finite number"):
        pinned.modes(speed=float("nan"))


def test_a_planar_run_3d_scene_has_its_flap_modes():
    """Issue 44's defect 2: a 3D blade that runs with the planar element keeps its out-of-plane
    (flap) mode: mode 1 at the 0.01 m thickness's frequency, its shape along z."""
    blade = beam(HUB, "geometric_stiffening = true", dimensions=3, section="a = 0.02, b = 0.01")
    m = blade.modes(count=2)
    assert m.runs_planar
    assert list(m) == pytest.approx([clamped_free(1.875_104_1), clamped_free(1.875_104_1, 0.02)], rel=1e-4)
    assert m.coordinates[int(np.argmax(np.abs(m.shapes[:, 0])))].startswith("beam.shape.z[")
    assert m.coordinates[int(np.argmax(np.abs(m.shapes[:, 1])))].startswith("beam.shape.y[")


def test_campbell_is_the_command_line_diagram_on_any_number_of_threads(tmp_path):
    scene_file = tmp_path / "blade.toml"
    blade = beam(HUB, "geometric_stiffening = true")
    scene_file.write_text(blade.to_toml())
    speeds = np.linspace(0.0, 8.0, 9)
    one = blade.campbell(speeds, count=3, jobs=1)
    two = blade.campbell(list(speeds), count=3, jobs=2)
    pd.testing.assert_frame_equal(one, two, check_exact=True)
    assert one.index.name == "speed" and list(one.columns) == ["mode1", "mode2", "mode3"]
    assert np.array_equal(one.index.to_numpy(), speeds)
    assert one.attrs["units"] == {"speed": "rad/s", "mode1": "Hz", "mode2": "Hz", "mode3": "Hz"}
    assert one.attrs["hub"] == "hub" and not one.attrs["damped"]
    # each row is Scene.modes at that speed, and the CSV of `fmu-beam modes --campbell`, bit for bit
    assert list(one.loc[4.0]) == blade.modes(count=3, speed=4.0)
    prefix = tmp_path / "c"
    status = fmu_beam.main(["modes", str(scene_file), "--count", "3", "--campbell", "0:8:9", "-o", str(prefix)])
    assert status == 0
    csv = pd.read_csv(tmp_path / "c.csv", index_col=0)
    assert np.array_equal(csv.to_numpy(), one.to_numpy()) and np.array_equal(csv.index.to_numpy(), speeds)
    assert blade.campbell([], count=3).empty
    with pytest.raises(fmu_beam.Error, match="jobs"):
        blade.campbell(speeds, jobs=0)


def test_campbell_of_a_damped_scene_has_its_damping_ratios():
    beta = 1e-3
    scene = beam(HUB, f"geometric_stiffening = true\nrayleigh = {{ alpha = 0.0, beta = {beta} }}")
    df = scene.campbell([0.0, 4.0], count=2)
    assert list(df.columns) == ["mode1", "mode2", "damping_ratio1", "damping_ratio2"]
    assert df.attrs["units"]["damping_ratio1"] == "1" and df.attrs["damped"]
    # at rest beta*omega/2 (the hub held: the clamped beam): measured 1.8e-7 off (the damping
    # of the stiffened strain's rate adds it; 1e-7 relative without stiffening)
    for k in (1, 2):
        zeta = beta * math.pi * df.loc[0.0, f"mode{k}"]
        assert df.loc[0.0, f"damping_ratio{k}"] == pytest.approx(zeta, abs=1e-6)
    assert (df.loc[4.0, ["damping_ratio1", "damping_ratio2"]] > 0).all()
    assert df.loc[4.0, "mode1"] > df.loc[0.0, "mode1"]
