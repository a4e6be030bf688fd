"""Illegal use, one matrix run on an FMI 2.0 and an FMI 3.0 unit of the same scene (issue 47:
"the same test matrix, run on both"): illegal call sequences in each state, NULL pointers,
unknown value references, NaN inputs and parameters, a fixed parameter set after initialization,
bad step times. Each misuse returns Error (fmpy's FMICallException with status 3), the unit's
logger gets a message saying why, and the instance is as it was: its outputs equal those of a
twin instance that never saw the misuse, bit for bit, and so do its outputs after the steps that
follow. A fresh instance afterwards runs.

The cases are written once against a thin adapter per version (`Unit2` over fmpy's FMU2Slave,
`Unit3` over FMU3Slave): the same call in each version's words (fmi2SetupExperiment +
fmi2EnterInitializationMode or fmi3EnterInitializationMode, fmi2GetReal or fmi3GetFloat64, ...).
The scene, the split slider-crank's rod in force causality, has an input (`pin.fx`), a tunable
parameter (`solver.tolerance`), a fixed one (`rod.E`) and shape arrays (in 3.0)."""

import ctypes
import math

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2Real, fmi2ValueReference
from fmpy.fmi3 import FMU3Slave, fmi3Boolean, fmi3Float64, fmi3ValueReference

from fmu_util import Logger

SCENE = "slider_crank_split_rod_force"
ERROR = 3
STATES = ["Instantiated", "InitializationMode", "StepMode", "Terminated"]


class Unit:
    """One instance of the scene's unit in one FMI version, with the calls the matrix makes."""

    version = None

    def __init__(self, path, where, name):
        self.md = read_model_description(path)
        self.vars = {v.name: v for v in self.md.modelVariables}
        ex = self.md.defaultExperiment
        self.t, self.h = float(ex.startTime or 0.0), float(ex.stepSize)
        self.state = "Instantiated"
        self.fmu = self.slave(extract(path, unzipdir=where), name)

    def vr(self, name):
        return self.vars[name].valueReference

    def unknown_vr(self):
        return max(v.valueReference for v in self.md.modelVariables) + 1000

    def output_vrs(self):
        return [v.valueReference for v in self.md.modelVariables
                if v.causality == "output" and v.type in ("Real", "Float64")]

    def bits(self):
        """Every Real output (an array's elements), as bits."""
        return np.asarray(self.get(self.output_vrs()), dtype=float).view(np.uint64).tolist()

    def step(self, n=1):
        for _ in range(n):
            self.do_step(self.t, self.h)
            self.t += self.h

    def reach(self, state):
        """From Instantiated along the standard's path to `state`."""
        path = STATES[:STATES.index(state) + 1]
        for reached in path[1:]:
            if reached == "InitializationMode":
                self.enter()
            elif reached == "StepMode":
                self.fmu.exitInitializationMode()
            else:
                self.step()
                self.fmu.terminate()
            self.state = reached

    def errors(self):
        return [m for s, m in self.messages() if s == ERROR]

    def close(self):
        self.fmu.freeInstance()


class Unit2(Unit):
    version = 2

    def slave(self, unzipdir, name):
        self.logger = Logger()
        fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipdir,
                        modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        fmu.instantiate(callbacks=self.logger.callbacks, loggingOn=True)
        return fmu

    def messages(self):
        return [(s, m) for s, _, m in self.logger.messages]

    def enter(self):
        self.fmu.setupExperiment(startTime=self.t)
        self.fmu.enterInitializationMode()

    def do_step(self, t, h):
        self.fmu.doStep(t, h)

    def get(self, vrs):
        return self.fmu.getReal(vrs)

    def set(self, vrs, values):
        self.fmu.setReal(vrs, values)

    def null_pointer_calls(self):
        f, c = self.fmu, self.fmu.component
        out = (fmi2ValueReference * 1)(self.output_vrs()[0])
        into = (fmi2ValueReference * 1)(self.vr("pin.fx"))
        return {
            "get values NULL": lambda: f.fmi2GetReal(c, out, 1, None),
            "get references NULL": lambda: f.fmi2GetReal(c, None, 1, (fmi2Real * 1)()),
            "set values NULL": lambda: f.fmi2SetReal(c, into, 1, None),
            "state NULL": lambda: f.fmi2GetFMUstate(c, None),
        }


class Unit3(Unit):
    version = 3

    def slave(self, unzipdir, name):
        self.log = []
        fmu = FMU3Slave(guid=self.md.guid, unzipDirectory=unzipdir,
                        modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        fmu.instantiate(loggingOn=True, logMessage=self.record)
        return fmu

    def record(self, env, status, category, message):
        self.log.append((status, (message or b"").decode("utf-8", "replace")))

    def messages(self):
        return self.log

    def values(self, vrs):
        """How many values `vrs` hold (an array's elements)."""
        by_vr = {v.valueReference: v for v in self.md.modelVariables}
        return sum(int(np.prod([int(d.start) for d in by_vr[r].dimensions]))
                   if r in by_vr and by_vr[r].dimensions else 1 for r in vrs)

    def enter(self):
        self.fmu.enterInitializationMode(startTime=self.t)

    def do_step(self, t, h):
        event, terminate, early, last = self.fmu.doStep(t, h)
        assert not (event or terminate or early)

    def get(self, vrs):
        return self.fmu.getFloat64(vrs, nValues=self.values(vrs))

    def set(self, vrs, values):
        self.fmu.setFloat64(vrs, values)

    def null_pointer_calls(self):
        f, c = self.fmu, self.fmu.component
        vr = self.output_vrs()[0]
        n = self.values([vr])
        out = (fmi3ValueReference * 1)(vr)
        into = (fmi3ValueReference * 1)(self.vr("pin.fx"))
        flag, last = fmi3Boolean(), fmi3Float64()
        return {
            "get values NULL": lambda: f.fmi3GetFloat64(c, out, 1, None, n),
            "get references NULL": lambda: f.fmi3GetFloat64(c, None, 1, (fmi3Float64 * n)(), n),
            "set values NULL": lambda: f.fmi3SetFloat64(c, into, 1, None, 1),
            "state NULL": lambda: f.fmi3GetFMUState(c, None),
            "doStep output NULL": lambda: f.fmi3DoStep(
                c, self.t, self.h, fmi3Boolean(False), None, ctypes.byref(flag),
                ctypes.byref(flag), ctypes.byref(last)),
        }


UNITS = {2: Unit2, 3: Unit3}


@pytest.fixture(params=[2, 3], ids=["fmi2", "fmi3"])
def units(request, packaged, tmp_path):
    """A factory of instances of the scene's unit in one version; each freed after the test."""
    made = []

    def make(name):
        unit = UNITS[request.param](packaged[SCENE, request.param], tmp_path / name, name)
        made.append(unit)
        return unit

    yield make
    for u in made:
        u.close()


def refused(unit, call, *hints):
    """`call` raises FMICallException(Error) and the logger got an error that names `hints`."""
    before = len(unit.errors())
    with pytest.raises(FMICallException) as e:
        call()
    assert e.value.status == ERROR, e.value
    errors = unit.errors()[before:]
    assert errors, f"no Error message logged: {unit.messages()}"
    for h in hints:
        assert any(h in m for m in errors), f"{h!r} not in {errors}"


def as_it_was(bad, twin):
    """`bad` (which saw a refused call) and `twin` (which did not) are in the same state: the same
    outputs now (where they can be read) and after the steps to come, bit for bit."""
    if bad.state in ("InitializationMode", "StepMode", "Terminated"):
        assert bad.bits() == twin.bits()
    if bad.state == "Terminated":
        return
    for u in (bad, twin):
        for state in STATES[STATES.index(u.state) + 1:3]:
            {"InitializationMode": u.enter, "StepMode": u.fmu.exitInitializationMode}[state]()
            u.state = state
    for _ in range(3):
        bad.step()
        twin.step()
        assert bad.bits() == twin.bits()


# The call-sequence table of the standards (FMI 2.0 §4.2.4 and FMI 3.0 §4.2.5, co-simulation
# without event mode; the two agree on these calls): which call each state takes ("ok") or
# refuses with Error and "illegal call sequence", changing nothing ("error").
SEQUENCE = {
    "Instantiated": dict(enter="ok", exit="error", step="error", get="error", set="ok",
                         terminate="error"),
    "InitializationMode": dict(enter="error", exit="ok", step="error", get="ok", set="ok",
                               terminate="error"),
    "StepMode": dict(enter="error", exit="error", step="ok", get="ok", set="ok", terminate="ok"),
    "Terminated": dict(enter="error", exit="error", step="error", get="ok", set="error",
                       terminate="error"),
}

CALLS = {
    "enter": lambda u: u.enter(),
    "exit": lambda u: u.fmu.exitInitializationMode(),
    "step": lambda u: u.do_step(u.t, u.h),
    "get": lambda u: u.get([u.vr("pin.ax")]),
    "set": lambda u: u.set([u.vr("solver.tolerance")], [float(u.vars["solver.tolerance"].start)]),
    "terminate": lambda u: u.fmu.terminate(),
}


@pytest.mark.parametrize("state", STATES)
def test_each_state_takes_the_calls_of_the_standards_table_and_refuses_the_rest(units, state):
    for name, expected in SEQUENCE[state].items():
        u = units(f"{name}_{state}")
        u.reach(state)
        if expected == "ok":
            CALLS[name](u)
            continue
        twin = units(f"{name}_{state}_twin")
        twin.reach(state)
        refused(u, lambda: CALLS[name](u), "illegal call sequence")
        as_it_was(u, twin)


# Misuses in Step Mode: (name, call, words the message holds).
MISUSES = [
    ("unknown value reference, get", lambda u: u.get([u.unknown_vr()]),
     lambda u: [str(u.unknown_vr())]),
    ("unknown value reference, set", lambda u: u.set([u.unknown_vr()], [1.0]),
     lambda u: [str(u.unknown_vr())]),
    ("NaN input", lambda u: u.set([u.vr("pin.fx")], [math.nan]),
     lambda u: ["pin.fx", "not a finite number"]),
    ("infinite input", lambda u: u.set([u.vr("pin.fx")], [math.inf]),
     lambda u: ["pin.fx", "not a finite number"]),
    ("NaN tunable parameter", lambda u: u.set([u.vr("solver.tolerance")], [math.nan]),
     lambda u: ["solver.tolerance"]),
    ("fixed parameter after initialization", lambda u: u.set([u.vr("rod.E")], [1e9]),
     lambda u: ["rod.E"]),
    ("negative step", lambda u: u.do_step(u.t, -u.h), lambda u: []),
    ("step from another time", lambda u: u.do_step(u.t + u.h, u.h), lambda u: []),
    ("NaN step", lambda u: u.do_step(u.t, math.nan), lambda u: []),
]


@pytest.mark.parametrize("name,call,words", MISUSES, ids=[m[0] for m in MISUSES])
def test_a_misuse_is_an_error_that_changes_nothing(units, name, call, words):
    bad, twin = units("bad"), units("twin")
    for u in (bad, twin):
        u.reach("StepMode")
        u.step(5)
        u.set([u.vr("pin.fx")], [2.0])
    refused(bad, lambda: call(bad), *words(bad))
    as_it_was(bad, twin)


@pytest.mark.parametrize("case", ["get values NULL", "get references NULL", "set values NULL",
                                  "state NULL", "doStep output NULL"])
def test_a_null_pointer_is_an_error_that_changes_nothing(units, case):
    bad, twin = units("bad"), units("twin")
    for u in (bad, twin):
        u.reach("StepMode")
        u.step(5)
    calls = bad.null_pointer_calls()
    if case not in calls:
        pytest.skip(f"FMI {bad.version} has no such pointer")
    refused(bad, calls[case], "NULL")
    as_it_was(bad, twin)


def test_a_fresh_instance_runs_after_misuse(units):
    bad = units("bad")
    refused(bad, lambda: bad.do_step(0.0, bad.h), "illegal call sequence")
    bad.reach("StepMode")
    refused(bad, lambda: bad.set([bad.vr("pin.fx")], [math.nan]), "pin.fx")
    fresh = units("fresh")
    fresh.reach("StepMode")
    fresh.step(5)
    assert all(math.isfinite(v) for v in fresh.get(fresh.output_vrs()))
