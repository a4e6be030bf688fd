"""Illegal use gets fmi2Error and a log message, never a crash: each misuse below raises fmpy's
FMICallException with status fmi2Error, the FMU's logger callback receives a message, and the
process goes on (a fresh instance afterwards still runs)."""

import math

import pytest
from fmpy.fmi1 import FMICallException

from fmu_util import C1, all_finite, fmi2Error


def call_fails(inst, call, *hints):
    """`call` raises FMICallException(fmi2Error) and the logger got an error message that
    mentions each of `hints`."""
    with pytest.raises(FMICallException) as e:
        call()
    assert e.value.status == fmi2Error, f"{e.value}\n{inst.logger.text()}"
    errors = inst.logger.errors()
    assert errors, f"no fmi2Error message logged:\n{inst.logger.text()}"
    for h in hints:
        assert any(h in m for m in errors), f"{h!r} not in the messages:\n{inst.logger.text()}"


def do_step_before_initialization(inst):
    call_fails(inst, lambda: inst.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=inst.step_size))


def get_real_unknown_value_reference(inst):
    inst.initialize()
    unknown = max(v.valueReference for v in inst.md.modelVariables) + 1000
    call_fails(inst, lambda: inst.fmu.getReal([unknown]), str(unknown))


def negative_step_size(inst):
    inst.initialize()
    inst.step(2)
    call_fails(inst, lambda: inst.fmu.doStep(currentCommunicationPoint=inst.time, communicationStepSize=-inst.step_size))


def set_fixed_parameter_after_initialization(inst):
    inst.initialize()
    assert inst.vars["beam.E"].variability == "fixed"
    call_fails(inst, lambda: inst.fmu.setReal([inst.vr("beam.E")], [1e9]), "beam.E")


def nan_into_solver_tolerance(inst):
    call_fails(inst, lambda: inst.fmu.setReal([inst.vr("solver.tolerance")], [math.nan]), "solver.tolerance")


MISUSES = [
    do_step_before_initialization,
    get_real_unknown_value_reference,
    negative_step_size,
    set_fixed_parameter_after_initialization,
    nan_into_solver_tolerance,
]


@pytest.mark.parametrize("misuse", MISUSES, ids=[m.__name__ for m in MISUSES])
def test_misuse_is_an_error_with_a_message_and_the_process_survives(new_instance, misuse):
    bad = new_instance(f"{C1}_bad")
    misuse(bad)
    bad.close()

    fresh = new_instance(f"{C1}_fresh")
    fresh.initialize()
    rows = fresh.step(5)
    assert all(all_finite(r) for r in rows)
    assert fresh.fmu.getReal([fresh.vr("beam.tip.deflection")])[0] != 0.0


def test_nan_tolerance_after_initialization_is_refused_and_the_instance_keeps_its_value(new_instance):
    inst = new_instance(f"{C1}_nan")
    inst.initialize()
    vr = inst.vr("solver.tolerance")
    before = inst.fmu.getReal([vr])[0]
    call_fails(inst, lambda: inst.fmu.setReal([vr], [math.nan]), "solver.tolerance")
    assert inst.fmu.getReal([vr])[0] == before
