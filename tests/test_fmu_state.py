"""Rollback and restart: fmi2GetFMUstate / fmi2SetFMUstate and their serialized form restore
an instance exactly, so running from the restored state repeats the first run bit for bit."""

import struct

from fmu_util import C1

# Communication steps before the saved state and after it.
STEPS_TO_T1 = 50
STEPS_T1_T2 = 50


def bits(rows):
    """Outputs as their exact binary representation (NaN-safe, -0.0 distinct)."""
    return [tuple(struct.pack("<d", v) if isinstance(v, float) else v for v in row) for row in rows]


def test_get_and_set_state_repeats_the_run_bit_for_bit(new_instance):
    a = new_instance(f"{C1}_a")
    a.initialize()
    a.step(STEPS_TO_T1)
    t1 = a.time
    state = a.fmu.getFMUstate()
    first = a.step(STEPS_T1_T2)

    a.fmu.setFMUstate(state)
    a.time = t1
    again = a.step(STEPS_T1_T2)
    assert bits(again) == bits(first)

    # the state stays valid after being used, and can be set more than once
    a.fmu.setFMUstate(state)
    a.time = t1
    assert bits(a.step(STEPS_T1_T2)) == bits(first)
    a.fmu.freeFMUstate(state)


def test_serialized_state_restores_in_the_same_and_in_a_fresh_instance(new_instance):
    a = new_instance(f"{C1}_a")
    a.initialize()
    a.step(STEPS_TO_T1)
    t1 = a.time
    state = a.fmu.getFMUstate()
    blob = a.fmu.serializeFMUstate(state)
    a.fmu.freeFMUstate(state)
    assert isinstance(blob, bytes) and len(blob) > 0
    first = a.step(STEPS_T1_T2)

    # into the same instance
    restored = a.fmu.deSerializeFMUstate(blob)
    a.fmu.setFMUstate(restored)
    a.fmu.freeFMUstate(restored)
    a.time = t1
    assert bits(a.step(STEPS_T1_T2)) == bits(first)

    # into a fresh instance, initialized as a master would before restarting from a file
    b = new_instance(f"{C1}_b")
    b.initialize()
    restored = b.fmu.deSerializeFMUstate(blob)
    b.fmu.setFMUstate(restored)
    b.fmu.freeFMUstate(restored)
    b.time = t1
    assert bits(b.step(STEPS_T1_T2)) == bits(first)


def test_serialization_is_stable(new_instance):
    """Serializing the same state twice gives the same bytes."""
    a = new_instance(f"{C1}_a")
    a.initialize()
    a.step(10)
    state = a.fmu.getFMUstate()
    assert a.fmu.serializeFMUstate(state) == a.fmu.serializeFMUstate(state)
    a.fmu.freeFMUstate(state)
