"""Issue 32: a failed step names the cause the unit can see. The new user's two-link aluminium
arm (tests/scenes/two_link_arm.toml) under a PD loop in Python, sampled every 1 ms, as their
script ran it through fmpy: the torques act on the effective inertia of the beam elements next
to each joint (about 1e-5 kg m² against the 0.06-0.08 kg m² the attached bodies present held
rigid), the loop over-corrects them at every step and the step fails. The unit says so at
initialization (information: status fmi2OK, category logInformation, since issue 46: the unit
cannot see the loop, and an ordinary run needs nothing), and the Discard's message names the input, its effective inertia and the
sampled loop's limit, not a spin near a bending frequency. With a shoulder rotor and inertia on
both sides of the elbow (two_link_arm_motors.toml) the same loop runs clean and nothing is
said; with the elbow's stator inertia set to 0 the elbow alone is named. And a loop simply
too fast for a large enough rotor (the shipped flexible_arm_hub at 4 × the example's gains) is
named by the gain the unit saw it apply, 1.19 × the sampled limit.

The figures asserted come from `unit::input_inertia` (1 / (bᵀ M̃⁻¹ b)); the elements' own
inertia ρAL³/105 bounds them from above (a 0.15 m element of 40 × 6 mm aluminium: 2.1e-5 kg m²;
the Schur complement over the beam's other coordinates is about half of that)."""

import re

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException

from fmu_util import ROOT, Instance, fmi2Discard, fmi2OK, fmi2Warning, run_harness

SCENES = ROOT / "tests" / "scenes"
H = 1e-3
# rigid-arm inertias the gains are designed on (kg m²): shoulder with the whole arm, elbow with
# the lower link and payload; closed-loop poles at -10 rad/s (critically damped PD)
DESIGN = {"shoulder": 0.9, "elbow": 0.15}
OMEGA = 10.0
TARGET = 0.2


@pytest.fixture(scope="module")
def arms(harness, tmp_path_factory):
    out = {}
    for name in ("two_link_arm", "two_link_arm_motors"):
        fmu = tmp_path_factory.mktemp("arm") / f"{name}.fmu"
        r = run_harness(harness, "package", SCENES / f"{name}.toml", "-o", fmu)
        assert r.returncode == 0, r.stderr
        out[name] = (extract(fmu), read_model_description(fmu))
    return out


def run_pd(unit, start=None, duration=0.3):
    """The user's loop: read each joint's angle and speed, set a PD torque, doStep(1 ms).
    Returns (the time reached, the Discard message or None, the warnings, the information)."""
    inst = Instance(*unit, name="arm")
    try:
        for name, value in (start or {}).items():
            inst.fmu.setReal([inst.vr(name)], [value])
        inst.initialize(0.0)
        t, discard = 0.0, None
        while t < duration - 1e-9:
            for j, J in DESIGN.items():
                a, w = inst.fmu.getReal([inst.vr(f"{j}.angle"), inst.vr(f"{j}.speed")])
                torque = J * OMEGA**2 * (TARGET - a) - 2 * J * OMEGA * w
                inst.fmu.setReal([inst.vr(f"{j}.drive.torque")], [torque])
            try:
                inst.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=H)
            except FMICallException as e:
                assert e.status == fmi2Discard
                discard = [m for s, _, m in inst.logger.messages if s == fmi2Discard][-1]
                break
            t += H
        warnings = [m for s, _, m in inst.logger.messages if s == fmi2Warning]
        notes = [m for s, c, m in inst.logger.messages if (s, c) == (fmi2OK, "logInformation")]
        return t, discard, warnings, notes
    finally:
        inst.close()


def figure(text, pattern):
    m = re.search(pattern, text)
    assert m, f"{pattern!r} not in {text}"
    return float(m.group(1))


def inertia_named(text, joint):
    return figure(text, rf"input '{joint}.drive.torque' acts on an effective inertia of ([0-9.e+-]+) kg m²")


def test_the_bare_arm_is_told_and_its_failure_names_the_shoulders_small_inertia(arms):
    t, discard, warnings, notes = run_pd(arms["two_link_arm"])
    assert discard is not None and t < 0.05, f"the bare arm ran to {t} s"
    # at initialization: both inputs, with their figures (1.16e-5 and 1.07e-6 kg m² measured),
    # as information, not warnings
    assert not [w for w in warnings if "acts on an effective inertia" in w], warnings
    (shoulder,) = [w for w in notes if "'shoulder.drive.torque' acts on" in w]
    (elbow,) = [w for w in notes if "'elbow.drive.torque' acts on" in w]
    j_shoulder = inertia_named(shoulder, "shoulder")
    assert 5e-6 < j_shoulder < 2.1e-5, j_shoulder  # below the root element's ρAL³/105
    assert 1e-7 < inertia_named(elbow, "elbow") < 2.1e-5
    assert "add rotor or hub inertia" in shoulder
    # the failure: the shoulder's small inertia at h = 1 ms, the limit, the observed feedback
    assert inertia_named(discard, "shoulder") == pytest.approx(j_shoulder, rel=1e-3)
    assert "at the communication step h = 1.000e-3 s" in discard
    limit = figure(discard, r"damping gain below 2J/h = ([0-9.e+-]+) N m s/rad")
    assert limit == pytest.approx(2 * j_shoulder / H, rel=2e-3)
    # the loop's kd = 2 J ω = 18 N m s/rad, seen through Δτ/Δω (its stiffness share aside)
    seen = figure(discard, r"changed by [0-9.e+-]+ rad/s: a feedback of about ([0-9.e+-]+) N m s/rad")
    assert seen == pytest.approx(2 * DESIGN["shoulder"] * OMEGA, rel=0.1)
    assert "spins at" not in discard and "bending frequency" not in discard


def test_the_arm_with_inertia_on_both_sides_of_each_joint_runs_clean_and_unwarned(arms):
    t, discard, warnings, notes = run_pd(arms["two_link_arm_motors"])
    assert discard is None, discard
    assert t == pytest.approx(0.3)
    assert not warnings, warnings
    assert not [w for w in notes if "acts on an effective inertia" in w], notes


def test_an_elbow_with_inertia_on_one_side_only_fails_and_is_named_alone(arms):
    t, discard, _, notes = run_pd(arms["two_link_arm_motors"], {"elbow_stator.inertia": 0.0})
    assert discard is not None and t < 0.05, f"ran to {t} s"
    (warned,) = [w for w in notes if "acts on an effective inertia" in w]
    j_elbow = inertia_named(warned, "elbow")
    assert 5e-6 < j_elbow < 2.1e-5, j_elbow  # the upper link's tip element alone
    assert inertia_named(discard, "elbow") == pytest.approx(j_elbow, rel=1e-3)
    assert "shoulder.drive.torque" not in discard  # 0.2 kg m² rotor: kd h / J = 0.09
    seen = figure(discard, r"a feedback of about ([0-9.e+-]+) N m s/rad")
    assert seen == pytest.approx(2 * DESIGN["elbow"] * OMEGA, rel=0.1)


def test_a_loop_too_fast_for_a_rotor_is_named_by_the_gain_it_was_seen_to_apply(fmu_dir):
    # the shipped arm on its 5 kg m² rotor (not small: 12.7 % of 39.47 kg m²) under a PD of
    # 4 × the example's gains (kd = 1184 N m s/rad) at h = 10 ms: kd h / J = 2.4, beyond the
    # sampled limit 2; the unit cannot know kd, it sees it as Δτ/Δω between two points
    path = fmu_dir / "flexible_arm_hub.fmu"
    unit = extract(path), read_model_description(path)
    inst = Instance(*unit, name="hub")
    try:
        inst.initialize(0.0)
        kp, kd, h, t = 4 * 740.0, 4 * 296.0, 0.01, 0.0
        with pytest.raises(FMICallException):
            while t < 2.0:
                a, w = inst.fmu.getReal([inst.vr("hub.angle"), inst.vr("hub.speed")])
                inst.fmu.setReal([inst.vr("hub.drive.torque")], [kp * (0.5 * min(t, 1.0) - a) - kd * w])
                inst.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
                t += h
        discard = [m for s, _, m in inst.logger.messages if s == fmi2Discard][-1]
        # not small (12.7 %): nothing said at initialization, as a warning or as information
        assert not [m for s, _, m in inst.logger.messages if s < fmi2Discard and "acts on an effective" in m]
    finally:
        inst.close()
    assert inertia_named(discard, "hub") == pytest.approx(5.004, abs=0.01)
    seen = figure(discard, r"a feedback of about ([0-9.e+-]+) N m s/rad")
    assert seen == pytest.approx(kd, rel=0.05)
    assert figure(discard, r"N m s/rad, ([0-9.]+) × that limit") == pytest.approx(kd * h / (2 * 5.004), rel=0.05)
