"""Issue 31: a rigid body's mass and centre of mass, a load's force and scale law, a drive's law,
a joint's start and gravity are FMU parameters; set through fmpy's start values they give the
same results, bit for bit, as packaging the scene with the values written in."""

import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from fmu_util import run_harness

SCENE = """
name = "swept_arm"
[world]
gravity = [0.0, -9.81]
[experiment]
stop_time = 0.3
step_size = 1e-2
[[beam]]
name = "post"
length = 0.1
elements = 1
rigid = true
material = {{ rho = 7800.0, E = 2e11 }}
section = {{ A = 1e-4, J = 1e-9 }}
[[body]]
name = "arm"
mass = {mass}
inertia = 0.05
com = [{com_x}, 0.02]
frames = {{ tip = [0.6, 0.0] }}
[[joint]]
name = "base"
type = "weld"
frames = ["world", "post.a"]
[[joint]]
name = "hinge"
type = "revolute"
frames = ["world", "arm.origin"]
initial = {{ position = 0.4, speed = {speed} }}
drive = {{ kind = "effort", law = "exponential", value = {torque}, time_constant = 0.05, until = 0.15 }}
[[load]]
name = "push"
frame = "arm.tip"
force = [{fx}, -2.0]
torque = 0.5
scale = {{ law = "table", table = [[0.0, 0.0], [0.1, {row}], [0.2, 0.5]] }}
"""

PACKAGED = dict(mass=2.0, com_x=0.3, speed=2.0, torque=3.0, fx=1.0, row=1.0)
SWEPT = dict(mass=2.5, com_x=0.25, speed=5.0, torque=-2.0, fx=-1.0, row=2.0)
START_VALUES = {
    "arm.mass": 2.5,
    "arm.com.x": 0.25,
    "hinge.initial.speed": 5.0,
    "hinge.drive.value": -2.0,
    "push.fx": -1.0,
    "push.scale.table.value[2]": 2.0,
}
OUTPUTS = ["hinge.angle", "hinge.speed", "hinge.torque", "arm.x", "arm.y", "energy.total"]


def package(harness, tmp_path, folder, values, gravity=-9.81):
    scene = tmp_path / folder / "swept_arm.toml"
    scene.parent.mkdir()
    text = SCENE.format(**values).replace("[0.0, -9.81]", f"[0.0, {gravity!r}]")
    scene.write_text(text)
    fmu = tmp_path / folder / "swept_arm.fmu"
    r = run_harness(harness, "package", scene, "-o", fmu)
    assert r.returncode == 0, r.stderr
    return str(fmu)


def simulate(fmu, start_values=None):
    return simulate_fmu(
        fmu,
        stop_time=0.3,
        output_interval=0.01,
        start_values=start_values or {},
        output=OUTPUTS,
    )


def test_start_values_run_as_the_scene_with_the_values_written_in(harness, tmp_path):
    base = package(harness, tmp_path, "base", PACKAGED)
    swept = package(harness, tmp_path, "swept", SWEPT, gravity=-1.62)
    assert validate_fmu(base) == []
    md = read_model_description(base)
    declared = {v.name: v for v in md.modelVariables}
    for name in [*START_VALUES, "world.gravity.y", "arm.inertia", "hinge.initial.position"]:
        v = declared[name]
        # a load's force and torque are tunable; the rest changes the assembled system
        variability = "tunable" if name == "push.fx" else "fixed"
        assert (v.causality, v.variability) == ("parameter", variability), name
    assert declared["arm.inertia"].unit == "kg.m2"
    assert declared["arm.mass"].unit == "kg"
    by_parameters = simulate(base, {**START_VALUES, "world.gravity.y": -1.62})
    by_scene = simulate(swept)
    unchanged = simulate(base)
    for name in OUTPUTS:
        assert np.array_equal(by_parameters[name], by_scene[name]), name
    # and the parameters did change the run
    assert not np.array_equal(by_parameters["hinge.angle"], unchanged["hinge.angle"])
    # the joint's start: 0.4 rad at 5 rad/s
    assert abs(by_parameters["hinge.angle"][0] - 0.4) < 1e-12
    assert abs(by_parameters["hinge.speed"][0] - 5.0) < 1e-9


def test_a_master_changes_a_load_between_steps(harness, tmp_path):
    """fmpy sets the tunable push.fx in step mode, between two doSteps: accepted, and the run
    after it is the run of the scene packaged with that force (started from the same state:
    the load enters only through the table, which is 0 at the start, so up to the change at 0 s
    both are the same), while a fixed parameter set there is refused with fmi2Error."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave

    base = package(harness, tmp_path, "base", PACKAGED)
    swept = package(harness, tmp_path, "swept", dict(PACKAGED, fx=-1.0))

    def run(path, change):
        md = read_model_description(path)
        refs = {v.name: v.valueReference for v in md.modelVariables}
        fmu = FMU2Slave(
            guid=md.guid,
            unzipDirectory=extract(path),
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName="i",
        )
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        rows = []
        for k in range(30):
            if change and k == 0:
                fmu.setReal([refs["push.fx"]], [-1.0])
                try:
                    fmu.setReal([refs["arm.mass"]], [3.0])
                    refused = False
                except Exception:
                    refused = True
                assert refused, "a fixed parameter was accepted in step mode"
            fmu.doStep(currentCommunicationPoint=k * 0.01, communicationStepSize=0.01)
            rows.append(fmu.getReal([refs[n] for n in OUTPUTS]))
        fmu.terminate()
        fmu.freeInstance()
        return np.array(rows)

    tuned = run(base, True)
    packaged = run(swept, False)
    unchanged = run(base, False)
    # the change at t = 0 met as a jump (a restart there) against a run that starts with it:
    # the same equations from the same state, to the solver's tolerance (1e-6 by default)
    assert np.allclose(tuned, packaged, rtol=1e-5, atol=1e-7), np.abs(tuned - packaged).max()
    assert not np.allclose(tuned, unchanged, rtol=1e-5, atol=1e-7)
