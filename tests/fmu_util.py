"""Helpers for driving packaged FMUs through fmpy's FMU2Slave: a logger that records what the
FMU reports, and an instance wrapper with name lookup and stepping."""

import math
import subprocess
from pathlib import Path

from fmpy import calloc, free
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)

ROOT = Path(__file__).resolve().parent.parent
C1 = "cantilever_free_vibration"

fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal = range(5)


class Logger:
    """An fmi2CallbackLogger that keeps (status, category, message) of every call."""

    def __init__(self):
        self.messages = []

        def log(env, instance_name, status, category, message):
            self.messages.append(
                (
                    status,
                    (category or b"").decode("utf-8", "replace"),
                    (message or b"").decode("utf-8", "replace"),
                )
            )

        # ctypes callbacks and the struct must outlive the instance: keep them here
        self.logger = fmi2CallbackLoggerTYPE(log)
        self.allocate = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.free = fmi2CallbackFreeMemoryTYPE(free)
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self.logger
        self.callbacks.allocateMemory = self.allocate
        self.callbacks.freeMemory = self.free

    def errors(self):
        return [m for s, _, m in self.messages if s == fmi2Error]

    def text(self):
        return "\n".join(f"[{s}] {c}: {m}" for s, c, m in self.messages) or "(no messages)"


class Instance:
    """One FMU2Slave instance of an extracted FMU, with a recording logger and name lookup."""

    def __init__(self, unzipdir, md, name="instance", logging_on=True):
        self.md = md
        self.vars = {v.name: v for v in md.modelVariables}
        self.logger = Logger()
        self.closed = False
        self.fmu = FMU2Slave(
            guid=md.guid,
            unzipDirectory=unzipdir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        try:
            self.fmu.instantiate(callbacks=self.logger.callbacks, loggingOn=logging_on)
        except Exception:
            self.fmu.freeLibrary()
            self.closed = True
            raise
        # fmpy keeps DefaultExperiment attributes as the XML's strings
        self.step_size = float(md.defaultExperiment.stepSize)
        self.time = float(md.defaultExperiment.startTime or 0.0)
        self.real_outputs = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        self.int_outputs = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Integer"]

    def vr(self, name):
        return self.vars[name].valueReference

    def initialize(self, start_time=None):
        if start_time is not None:
            self.time = start_time
        self.fmu.setupExperiment(startTime=self.time)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def outputs(self):
        """All outputs, Reals then Integers, in value-reference order."""
        return tuple(self.fmu.getReal(self.real_outputs)) + tuple(self.fmu.getInteger(self.int_outputs))

    def step(self, n=1):
        """n communication steps of the default size; the outputs after each one."""
        rows = []
        for _ in range(n):
            self.fmu.doStep(currentCommunicationPoint=self.time, communicationStepSize=self.step_size)
            self.time += self.step_size
            rows.append(self.outputs())
        return rows

    def close(self):
        """fmi2FreeInstance and unload the library (idempotent)."""
        if self.closed:
            return
        self.closed = True
        if self.fmu.component is not None:
            self.fmu.fmi2FreeInstance(self.fmu.component)
            self.fmu.component = None
        self.fmu.freeLibrary()


def all_finite(values):
    return all(math.isfinite(v) for v in values)


def run_harness(harness, *args):
    return subprocess.run([str(harness), *map(str, args)], capture_output=True, text=True)


def harness_modes(harness, scene, count=10):
    """The scene's elastic natural frequencies (Hz) as `fmu-harness modes` prints them."""
    r = run_harness(harness, "modes", scene, "--count", count)
    if r.returncode != 0:
        raise RuntimeError(f"fmu-harness modes {scene} failed: {r.stderr}")
    return [float(line.split(":")[1].split()[0]) for line in r.stdout.splitlines() if line.startswith("mode ")]
