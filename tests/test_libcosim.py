"""A second FMI master (issue 6): case C2 (scenes/flexible_pendulum.toml) run by libcosim (the Open
Simulation Platform's co-simulation library, through libcosimpy) and by fmpy's FMU2Slave with the
same fixed communication steps gives the same outputs at every communication point, within 1e-9
relative (to the value, or to 1e-3 of the output's largest magnitude for entries near zero);
measured: bit for bit.

Both masters make the same calls (setup, initialization, doStep from t to t + h) and the engine is
deterministic. libcosim counts time in integer nanoseconds, and fmpy's usual t = k h differs from
its t by an ulp now and then; fmpy is driven here at libcosim's communication points. A unit
without inputs steps across communication points (issue 12) and interpolates its outputs at them,
so the internal steps do not depend on where the master puts them: fmpy at twice the
communication step gives the same outputs at the common points, within the same bound."""

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

SCENE = "flexible_pendulum"
OUTPUTS = ["beam.tip.deflection", "beam.tip.x", "beam.tip.y", "beam.mid.deflection", "hinge.angle",
           "hinge.speed", "energy.total"]
STEP_NS = 1_000_000  # 1e-3 s, the scene's default communication step
STEPS = 500  # 0.5 s: the pendulum swings past the vertical (hinge angle about -1.4 rad)
RTOL = 1e-9


@pytest.fixture(scope="module")
def pendulum(fmu_dir):
    path = fmu_dir / f"{SCENE}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} does not exist: run `make fmus` first")
    md = read_model_description(path)
    return path, md, {v.name: v.valueReference for v in md.modelVariables}


def run_libcosim(path, vrs, steps):
    """The outputs after each of `steps` communication steps of STEP_NS, from libcosim."""
    log_output_level(CosimLogLevel.WARNING)
    execution = CosimExecution.from_step_size(STEP_NS)
    observer = CosimObserver.create_last_value()
    assert execution.add_observer(observer)
    slave = CosimLocalSlave(str(path), "pendulum")
    index = execution.add_local_slave(slave)
    assert index >= 0, "libcosim could not load the FMU (see its log above)"
    rows = []
    for k in range(steps):
        assert execution.step(1), f"libcosim step {k} failed: {execution.status()}"
        rows.append(observer.last_real_values(index, vrs))
    status = execution.status()
    assert status.current_time == steps * STEP_NS
    return np.array(rows)


def communication_points(step_ns, steps):
    """(t, h) of each communication step as libcosim passes them: its clock counts integer
    nanoseconds and converts t = n / 1e9 and h = (n + step) / 1e9 - n / 1e9 (cosim/time.hpp,
    `to_double_time_point`, `to_double_duration`)."""
    return [(k * step_ns / 1e9, (k + 1) * step_ns / 1e9 - k * step_ns / 1e9) for k in range(steps)]


def run_fmpy(path, md, vrs, step_ns, steps, tmp_path):
    """The outputs after each of `steps` communication steps of `step_ns` nanoseconds, from fmpy,
    at the communication points libcosim uses."""
    unzip = extract(path, unzipdir=tmp_path / "unzipped")
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="pendulum")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    rows = []
    for t, h in communication_points(step_ns, steps):
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        rows.append(fmu.getReal(vrs))
    fmu.terminate()
    fmu.freeInstance()
    fmu.freeLibrary()
    return np.array(rows)


def relative_difference(a, b):
    """Per output, the largest |a - b| over the run relative to the values themselves, or to
    1e-3 of the output's largest magnitude over the run for entries near zero."""
    floor = 1e-3 * np.max(np.abs(b), axis=0)
    return np.max(np.abs(a - b) / np.maximum(np.maximum(np.abs(a), np.abs(b)), floor), axis=0)


def test_libcosim_equals_fmpy_on_c2(pendulum, tmp_path):
    path, md, vr = pendulum
    vrs = [vr[n] for n in OUTPUTS]
    ours = run_libcosim(path, vrs, STEPS)
    ref = run_fmpy(path, md, vrs, STEP_NS, STEPS, tmp_path)
    assert ours.shape == ref.shape == (STEPS, len(OUTPUTS))
    assert np.all(np.isfinite(ours))
    # the run is not trivial: the pendulum has swung down and its beam has bent
    assert ref[-1, OUTPUTS.index("hinge.angle")] < -1.0
    assert np.max(np.abs(ref[:, OUTPUTS.index("beam.tip.deflection")])) > 1e-4
    diff = relative_difference(ours, ref)
    print("libcosim vs fmpy, max relative difference per output:",
          dict(zip(OUTPUTS, (f"{d:.2e}" for d in diff))))
    bad = [f"{n}: {d:.3e}" for n, d in zip(OUTPUTS, diff) if not d <= RTOL]
    assert not bad, "libcosim and fmpy disagree: " + ", ".join(bad)


def test_a_different_communication_step_gives_the_same_outputs(pendulum, tmp_path):
    """fmpy at twice the step, compared at the common points: the unit's internal steps do not
    depend on the communication points (before issue 12 they landed on each of them, and the
    two runs differed by 4e-4 of the peak tip deflection)."""
    path, md, vr = pendulum
    vrs = [vr[n] for n in OUTPUTS]
    fine = run_fmpy(path, md, vrs, STEP_NS, STEPS, tmp_path / "fine")[1::2]
    coarse = run_fmpy(path, md, vrs, 2 * STEP_NS, STEPS // 2, tmp_path / "coarse")
    diff = relative_difference(fine, coarse)
    print("1 ms against 2 ms communication steps, max relative difference per output:",
          dict(zip(OUTPUTS, (f"{d:.2e}" for d in diff))))
    assert np.max(diff) <= RTOL, diff
