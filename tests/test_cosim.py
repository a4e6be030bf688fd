"""`fmu-harness cosim` and `simulate` against fmpy at the same communication steps:
- the C test FMU (tests/c/oscillator, built here): `simulate` equals fmpy's `simulate_fmu`, and a
  Jacobi coupling of two oscillators equals the same loop written with fmpy's FMU2Slave;
- our split slider-crank (examples/split_slider_crank): `cosim` equals cosim_fmpy.py;
- the split converges to the monolithic slider_crank unit as the communication step shrinks
  (crank 20x denser than C3's; with C3's own masses every explicit coupling diverges, see the
  example's README)."""

import csv
import re
import subprocess
import sys

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave

from fmu_util import ROOT

sys.path.insert(0, str(ROOT / "examples" / "split_slider_crank"))
import cosim_fmpy  # noqa: E402

RTOL = 1e-12


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(x) for x in r] for r in rows[1:]])


def assert_same(ours, ref, names):
    bad = []
    for j, name in enumerate(names):
        a, b = ours[:, j], ref[:, j]
        scale = max(np.max(np.abs(b)), np.finfo(float).tiny)
        allowed = RTOL * np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-3 * scale)
        if np.any(np.abs(a - b) > allowed):
            i = int(np.argmax(np.abs(a - b) - allowed))
            bad.append(f"{name}: row {i}: ours {a[i]!r}, fmpy {b[i]!r}")
    assert not bad, "\n".join(bad)


@pytest.fixture(scope="module")
def oscillator(tmp_path_factory):
    out = tmp_path_factory.mktemp("oscillator") / "oscillator.fmu"
    subprocess.run([ROOT / "tests" / "c" / "oscillator" / "build.sh", out], check=True)
    return out


def test_simulate_equals_fmpy_on_the_c_fmu(oscillator, harness, tmp_path):
    out = tmp_path / "sim.csv"
    subprocess.run([harness, "simulate", oscillator, "--stop", "2", "--step", "1e-2", "-o", out],
                   check=True)
    names, ours = read_csv(out)
    ref = simulate_fmu(oscillator, stop_time=2.0, output_interval=1e-2, output=names[1:])
    assert len(ref) == len(ours) == 201
    assert_same(ours, np.array([list(r) for r in ref]), names)


def fmpy_pair(fmu, h, stop):
    """Jacobi, held inputs, as fmu-harness cosim does it: start values, setup, initialization,
    one pass of coupling values, then per step set every input from the values at t and step."""
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    units = []
    for name, x0 in (("a", 0.1), ("b", 0.0)):
        s = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        s.instantiate(loggingOn=False)
        for k, v in (("dt", 1e-4), ("k", 100.0), ("k_c", 50.0), ("x0", x0)):
            s.setReal([vr[k]], [v])
        s.setupExperiment(startTime=0.0, stopTime=stop)
        s.enterInitializationMode()
        s.exitInitializationMode()
        units.append(s)
    a, b = units
    xa, xb = a.getReal([vr["x"]])[0], b.getReal([vr["x"]])[0]
    rows = [[0.0, xa, xb]]
    t, n = 0.0, 0
    while not (t > stop or abs(t - stop) <= 1e-9 * stop):
        target = (n + 1) * h
        if target > stop or abs(target - stop) <= 1e-9 * stop:
            target = stop
        b.setReal([vr["u"]], [xa])
        a.setReal([vr["u"]], [xb])
        a.doStep(t, target - t)
        b.doStep(t, target - t)
        xa, xb = a.getReal([vr["x"]])[0], b.getReal([vr["x"]])[0]
        t, n = target, n + 1
        rows.append([t, xa, xb])
    for s in units:
        s.terminate()
        s.freeInstance()
    return np.array(rows)


def test_cosim_equals_an_fmpy_loop_on_two_c_fmus(oscillator, harness, tmp_path):
    system = tmp_path / "pair.toml"
    system.write_text(f"""stop_time = 1.0
step = {{ size = 1e-2 }}
connections = ["a.x -> b.u", "b.x -> a.u"]
outputs = ["a.x", "b.x"]
[[unit]]
name = "a"
fmu = "{oscillator}"
start = {{ dt = 1e-4, k = 100.0, k_c = 50.0, x0 = 0.1 }}
[[unit]]
name = "b"
fmu = "{oscillator}"
start = {{ dt = 1e-4, k = 100.0, k_c = 50.0, x0 = 0.0 }}
""")
    out = tmp_path / "pair.csv"
    run = subprocess.run([harness, "cosim", system, "-o", out], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    print(run.stdout)
    names, ours = read_csv(out)
    ref = fmpy_pair(oscillator, 1e-2, 1.0)
    assert ours.shape == ref.shape == (101, 3)
    assert_same(ours, ref, names)


def test_cosim_equals_the_fmpy_script_on_the_split_slider_crank(fmu_dir, harness, tmp_path):
    out = tmp_path / "split.csv"
    system = ROOT / "examples" / "split_slider_crank" / "system.toml"
    run = subprocess.run([harness, "cosim", system, "-o", out], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    print(run.stdout)
    names, ours = read_csv(out)
    assert names == cosim_fmpy.header()
    ref = np.array(cosim_fmpy.run(step=1e-3, stop=0.3, rho=55400.0, fmu_dir=fmu_dir))
    assert ours.shape == ref.shape == (301, 6)
    assert_same(ours, ref, names)


def test_split_converges_to_the_monolithic_unit(fmu_dir):
    stop, rho = 0.3, 55400.0
    errors = []
    for h in (1e-3, 5e-4, 2.5e-4):
        split = np.array(cosim_fmpy.run(step=h, stop=stop, rho=rho, fmu_dir=fmu_dir))
        # the monolithic unit has no inputs: it steps across the communication points at its
        # own tolerance, tightened so that its time error stays below the coupling error
        ref = simulate_fmu(fmu_dir / "slider_crank.fmu", stop_time=stop, output_interval=h,
                           output=["crank.tip.y", "slider.position"],
                           start_values={"crank.rho": rho, "solver.adaptive": True,
                                         "solver.max_step": 1e-2, "solver.tolerance": 1e-9})
        assert len(ref) == len(split)
        tip = np.max(np.abs(split[:, 2] - ref["crank.tip.y"]))
        slider = np.max(np.abs(split[:, 3] - ref["slider.position"]))
        errors.append((h, tip, slider))
        print(f"h = {h:g}: max |tip y error| {tip:.3e} m, max |slider error| {slider:.3e} m")
    # The tip swings 4.9 mm in 0.3 s. Each halving of h must cut the tip error by a third at
    # least (first order would halve it), and the finest step must be within 1 % of the swing.
    for (_, t0, s0), (_, t1, s1) in zip(errors, errors[1:]):
        assert t1 < 0.67 * t0, errors
        assert s1 < 0.67 * s0, errors
    assert errors[-1][1] < 0.01 * 4.9e-3, errors
    # the split slider-crank's README quotes these figures to three digits
    readme = (ROOT / "examples" / "split_slider_crank" / "README.md").read_text()
    quoted = re.search(r"max \|crank tip y error\| ([^m]+) m and max \|slider error\| ([^m]+) m",
                       " ".join(readme.split()))
    assert quoted, "the README's finer-step figures"
    for column, text in ((1, quoted.group(1)), (2, quoted.group(2))):
        figures = [float(x) for x in text.split(",")]
        assert figures == [float(f"{e[column]:.2e}") for e in errors], (text, errors)


def test_gauss_seidel_linear_equals_held_where_one_rod_step_spans_each_communication_step(
        fmu_dir, harness, tmp_path):
    """Issue 31: with the 20x crank at h = 1 ms, Gauss-Seidel "linear" gives the CSV of "held".
    Not a bug: the rod takes one internal step per communication step, and its index-3
    generalized-alpha step meets the motion drive's position at the step's end only, which both
    schemes set to the crank tip's new position; the linear scheme's rate changes nothing there
    (its second derivative, zero, is what a quadratic one changes). With four internal steps per
    communication step the rod sees the positions in between, and the two differ: held fails,
    linear runs."""
    import study

    rod = str(study.FMUS.resolve() / "slider_crank_split_rod.fmu")

    def run(extrapolation, rod_max_step=None):
        text = study.system_text(1e-3, 0.05, "gauss-seidel", extrapolation, 55400.0)
        text = text.replace('"rod.slider.position"]', '"rod.slider.position", "rod.solver.steps"]')
        if rod_max_step:
            text = text.replace(f'fmu = "{rod}"', f'fmu = "{rod}"\nstart = {{ "solver.max_step" = {rod_max_step!r} }}')
        system, out = tmp_path / f"{extrapolation}.toml", tmp_path / f"{extrapolation}.csv"
        system.write_text(text)
        r = subprocess.run([harness, "cosim", system, "-o", out], capture_output=True, text=True)
        return (out.read_bytes() if r.returncode == 0 else None), r.stderr

    held, e = run("none")
    linear, _ = run("linear")
    assert held is not None and held == linear, e
    names, rows = read_csv(tmp_path / "linear.csv")
    steps = rows[:, names.index("rod.solver.steps")]
    assert steps[-1] == 50, "one internal step of the rod per communication step"
    held, e = run("none", 2.5e-4)
    linear, e_linear = run("linear", 2.5e-4)
    assert linear is not None, e_linear
    assert held is None and "fmi2Discard" in e, e
