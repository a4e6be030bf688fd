"""`Scene.simulate` (issue 44 item 1): the scene run in process with the unit's own engine equals
the packaged unit run through fmpy at the same settings, bit for bit: every shipped case C1-C4
and a 3D scene at their DefaultExperiment, start values, time series inputs (held and
interpolated through the input derivatives) and a controller written as a callable against the
same loop written with fmpy's FMU2Slave. A step the unit cannot take raises SimulationError with
the last good time, the reason and the rows so far; a wrong argument is refused before the run.

fmpy doubles its default output interval until at most 1000 steps remain; these runs pass the
scene's step explicitly, as Scene.simulate uses it."""

import math
import shutil

import numpy as np
import pandas as pd
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave

import fmu_beam
from fmu_util import ROOT

SCENES = ROOT / "scenes"


def scene(name):
    return fmu_beam.Scene.load(SCENES / f"{name}.toml")


def fmu(fmu_dir, name):
    path = fmu_dir / f"{name}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} does not exist: run `make fmus` first")
    return path


def assert_bit_equal(df, result):
    """Every column of `df` equals fmpy's record of it, bit for bit (NaN nowhere)."""
    assert np.array_equal(df.index.to_numpy(), result["time"])
    for name in df.columns:
        ours, theirs = df[name].to_numpy(), np.asarray(result[name])
        assert ours.dtype.kind == theirs.dtype.kind, name
        assert np.array_equal(ours, theirs), f"{name}: largest difference {np.max(np.abs(ours - theirs))}"


@pytest.mark.parametrize(
    "name",
    ["cantilever_free_vibration", "flexible_pendulum", "flexible_pendulum_substructured", "slider_crank",
     "spin_up_omega10", "pendulum_3d_double"],
)
def test_the_default_experiment_equals_fmpys_run_bit_for_bit(name, fmu_dir):
    s = scene(name)
    df = s.simulate()
    experiment = s.to_dict()["experiment"]
    result = simulate_fmu(str(fmu(fmu_dir, name)), output_interval=experiment["step_size"])
    assert df.index[-1] == pytest.approx(experiment["stop_time"])
    assert len(df) == len(result) > 10
    assert set(df.columns) == set(result.dtype.names) - {"time"}
    assert_bit_equal(df, result)
    # something moved: equal runs are not equal by standing still
    moving = [c for c in df.columns
              if df[c].dtype == np.float64 and df[c].abs().max() < 1e300 and df[c].std() > 0]
    assert len(moving) > 3


def test_outputs_units_and_start_values(fmu_dir):
    s = scene("flexible_pendulum")
    start = {"beam.E": 2e9}
    df = s.simulate(stop_time=0.3, outputs=["hinge.angle", "beam.tip.deflection", "solver.steps"],
                    start_values=start)
    assert list(df.columns) == ["hinge.angle", "beam.tip.deflection", "solver.steps"]
    assert df.index.name == "time"
    assert df.attrs["units"]["hinge.angle"] == "rad"
    assert df.attrs["units"]["beam.tip.deflection"] == "m"
    assert df["solver.steps"].dtype == np.int32
    result = simulate_fmu(str(fmu(fmu_dir, "flexible_pendulum")), stop_time=0.3, output_interval=1e-2,
                          output=list(df.columns), start_values=start)
    assert_bit_equal(df, result)
    # the start value was used: a stiffer beam deflects less
    nominal = s.simulate(stop_time=0.3, outputs=["beam.tip.deflection"])
    assert df["beam.tip.deflection"].abs().max() < 0.8 * nominal["beam.tip.deflection"].abs().max()


def ramp_inputs():
    """A torque on the flexible arm's hub: a ramp to 40 N m over 0.5 s, a step down to -20 N m at
    1.0 s (an event: two samples at one time), then held."""
    return pd.DataFrame({"hub.drive.torque": [0.0, 40.0, 40.0, -20.0, -20.0]},
                        index=pd.Index([0.0, 0.5, 1.0, 1.0, 2.0], name="time"))


def test_held_time_series_inputs_equal_fmpys_input(fmu_dir):
    s = scene("flexible_arm_hub")
    inputs = ramp_inputs()
    outputs = ["hub.angle", "hub.speed", "beam.tip.deflection"]
    df = s.simulate(stop_time=1.5, step_size=0.03, outputs=outputs, inputs=inputs, interpolation="hold")
    signals = np.array(list(zip(inputs.index, inputs["hub.drive.torque"])),
                       dtype=[("time", np.float64), ("hub.drive.torque", np.float64)])
    result = simulate_fmu(str(fmu(fmu_dir, "flexible_arm_hub")), stop_time=1.5, output_interval=0.03,
                          output=outputs, input=signals)
    assert_bit_equal(df, result)
    # a communication point lands on the event at 1.0 s (not on the 0.03 s grid)
    assert 1.0 in df.index
    assert df["hub.speed"].max() > 0.1


class Slave:
    """The packaged unit through fmpy's FMU2Slave, set up as simulate_fmu sets it up."""

    def __init__(self, path, unzipdir, stop):
        md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.unzipdir = extract(str(path), unzipdir=str(unzipdir))
        self.slave = FMU2Slave(guid=md.guid, unzipDirectory=self.unzipdir,
                               modelIdentifier=md.coSimulation.modelIdentifier)
        self.slave.instantiate()
        tolerance = md.defaultExperiment.tolerance
        self.slave.setupExperiment(tolerance=tolerance and float(tolerance), startTime=0.0, stopTime=stop)
        self.slave.enterInitializationMode()

    def get(self, names):
        return self.slave.getReal([self.vr[n] for n in names])

    def close(self):
        self.slave.terminate()
        self.slave.freeInstance()
        shutil.rmtree(self.unzipdir, ignore_errors=True)


def test_interpolated_inputs_are_the_piecewise_linear_series_through_the_derivatives(fmu_dir, tmp_path):
    """With interpolation="linear" the unit gets, at each communication point (the start in
    initialization mode included), the series' value and the slope of the segment ahead (after
    an event: the segment after the jump), through fmi2SetRealInputDerivatives. The reference is that loop written with fmpy's FMU2Slave, the
    slopes taken from the samples by hand (fmpy's own `set_input_derivatives=True` fails for one
    input: fmpy 0.3.32 sizes its buffer for 9)."""
    s = scene("flexible_arm_hub")
    inputs = ramp_inputs()  # 0 -> 40 over [0, 0.5], 40 until the event at 1.0, then -20
    outputs = ["hub.angle", "hub.speed", "beam.tip.deflection"]
    df = s.simulate(stop_time=1.5, step_size=0.03, outputs=outputs, inputs=inputs)  # linear: the default

    def ahead(t):
        """The value (w0 v0 + w1 v1, w0 = (t1 - t) / (t1 - t0)) and slope of the segment ahead."""
        if t < 0.5 - 1e-12:
            w0 = (0.5 - t) / 0.5
            return w0 * 0.0 + (1 - w0) * 40.0, 80.0
        return (40.0, 0.0) if t < 1.0 - 1e-12 else (-20.0, 0.0)

    unit = Slave(fmu(fmu_dir, "flexible_arm_hub"), tmp_path / "arm", 1.5)
    torque = [unit.vr["hub.drive.torque"]]
    unit.slave.setReal(torque, [0.0])
    unit.slave.setRealInputDerivatives(torque, [1], [80.0])  # the start's slope, in initialization
    unit.slave.exitInitializationMode()
    times = list(df.index)
    rows = [[0.0, *unit.get(outputs)]]
    for t, t_next in zip(times[:-1], times[1:]):
        value, slope = ahead(t)
        unit.slave.setReal(torque, [value])
        unit.slave.setRealInputDerivatives(torque, [1], [slope])
        unit.slave.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
        rows.append([t_next, *unit.get(outputs)])
    unit.close()
    expected = np.array(rows)
    assert 1.0 in df.index
    assert np.array_equal(df[outputs].to_numpy(), expected[:, 1:])


def test_linear_inputs_do_not_depend_on_the_communication_step():
    """Interpolated through the input derivatives, a piecewise-linear input is followed within each
    step, so a coarse and a fine communication grid see the same input; held, they do not."""
    s = scene("flexible_arm_hub")
    inputs = pd.DataFrame({"hub.drive.torque": [0.0, 40.0, 40.0]}, index=[0.0, 0.6, 2.0])
    runs = {}
    for interpolation in ("linear", "hold"):
        coarse = s.simulate(stop_time=0.6, step_size=0.2, outputs=["hub.angle"], inputs=inputs,
                            interpolation=interpolation)
        fine = s.simulate(stop_time=0.6, step_size=0.01, outputs=["hub.angle"], inputs=inputs,
                          interpolation=interpolation)
        runs[interpolation] = abs(coarse["hub.angle"].iloc[-1] - fine["hub.angle"].iloc[-1]) / abs(
            fine["hub.angle"].iloc[-1])
    # the solver's own error (fixed and adaptive steps differ by where they land) is far below the
    # hold's lag of half a coarse step on a ramp
    assert runs["linear"] < 1e-3
    assert runs["hold"] > 10 * runs["linear"]


def pd_torque(t, y):
    """A PD loop holding the hub at 0.5 rad."""
    return {"hub.drive.torque": 60.0 * (0.5 - y["hub.angle"]) - 25.0 * y["hub.speed"]}


def test_a_callable_controller_equals_the_same_loop_written_with_fmpy(fmu_dir, tmp_path):
    s = scene("flexible_arm_hub")
    outputs = ["hub.angle", "hub.speed", "beam.tip.deflection"]
    calls = []

    def controller(t, y):
        calls.append(t)
        return pd_torque(t, y)

    df = s.simulate(stop_time=2.0, step_size=0.01, outputs=outputs, inputs=controller)
    assert len(calls) == 200 and calls[0] == 0.0

    unit = Slave(fmu(fmu_dir, "flexible_arm_hub"), tmp_path / "arm", 2.0)
    unit.slave.exitInitializationMode()
    rows, t = [], 0.0
    for n in range(200):
        y = dict(zip(outputs, unit.get(outputs)))
        rows.append([t, *y.values()])
        unit.slave.setReal([unit.vr["hub.drive.torque"]], [pd_torque(t, y)["hub.drive.torque"]])
        t_next = (n + 1) * 0.01  # the communication points of simulate_fmu
        unit.slave.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
        t = t_next
    rows.append([t, *unit.get(outputs)])
    unit.close()
    expected = np.array(rows)
    assert np.array_equal(df.index.to_numpy(), expected[:, 0])
    assert np.array_equal(df[outputs].to_numpy(), expected[:, 1:])
    # the loop acted: the hub went towards 0.5 rad (from 0, with no torque but the loop's)
    assert 0.3 < df["hub.angle"].iloc[-1] < 0.8


def test_a_step_the_unit_cannot_take_raises_with_the_rows_so_far():
    """The single linear frame spun past its first bending frequency leaves its range at 4.43 s
    (docs/robustness.md): the unit ends the run there, and simulate says so."""
    s = scene("spin_up_omega10_single_frame")
    with pytest.raises(fmu_beam.SimulationError) as caught:
        s.simulate(outputs=["beam.tip.deflection"])
    e = caught.value
    assert isinstance(e, fmu_beam.Error)
    assert 4.0 < e.time < 4.6
    assert e.ended is True
    assert "range" in e.reason or "ran away" in e.reason or "runaway" in e.reason.lower()
    assert isinstance(e.rows, pd.DataFrame)
    assert e.rows.index[-1] == pytest.approx(e.time)
    assert np.isfinite(e.rows["beam.tip.deflection"]).all()


@pytest.mark.parametrize(
    "kwargs, says",
    [
        ({"outputs": ["no.such.output"]}, "no variable no.such.output"),
        ({"start_values": {"beam.nope": 1.0}}, "no variable beam.nope"),
        ({"start_values": {"beam.E": -1.0}}, "beam"),
        ({"stop_time": -1.0}, "must be after"),
        ({"step_size": 0.0}, "must be positive"),
        ({"step_size": math.nan}, "finite"),
        ({"stop_time": 1e6, "step_size": 1e-6}, "communication steps"),
        ({"inputs": {"time": [0.0, 1.0], "hinge.angle": [0.0, 1.0]}}, "no input hinge.angle"),
        ({"inputs": 3}, "inputs"),
        ({"interpolation": "cubic"}, "interpolation"),
    ],
)
def test_wrong_arguments_are_refused_before_the_run(kwargs, says):
    with pytest.raises(fmu_beam.Error, match=None) as caught:
        scene("flexible_pendulum").simulate(**kwargs)
    assert says in str(caught.value)


def test_a_scene_pickles_as_its_text():
    import pickle

    s = scene("pendulum_3d_matrix")
    back = pickle.loads(pickle.dumps(s))
    assert back == s
    assert len(pickle.dumps(s)) < 64_000


def test_information_goes_to_notes_and_warnings_to_messages():
    # issue 46: slider_crank's fixed step cut to land on its torque's cut-off at 0.7 s is
    # information (logging.info, attrs["notes"]), not a warning (attrs["messages"])
    df = scene("slider_crank").simulate()
    assert df.attrs["messages"] == []
    (note,) = df.attrs["notes"]
    assert "to land on a jump of a drive law" in note and "t = 0.7 s" in note
