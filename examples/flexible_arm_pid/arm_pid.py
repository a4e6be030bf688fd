"""A PID controller in Python drives the flexible arm unit (scenes/flexible_arm_hub.toml: the 8 m C4
beam welded to a 5 kg m^2 hub whose torque is the FMU input `hub.drive.torque`) through a
rest-to-rest hub move, in a scripted co-simulation with fmpy's FMU2Slave: at each communication
point the script reads the hub angle and speed, computes the torque, sets it (held over the step)
and steps the unit.

    .venv/bin/python examples/flexible_arm_pid/arm_pid.py [--fmu build/fmus/flexible_arm_hub.fmu] [-o DIR]

writes DIR/arm_pid.csv (time, reference, hub angle and speed, torque, tip deflection) and
DIR/arm_pid.png, and prints the figures of merit. Default DIR: build/examples/flexible_arm_pid.

    .venv/bin/python examples/flexible_arm_pid/arm_pid.py --table

runs the README's cases (CASES) instead and writes their figures into arm_pid_table.csv beside
this script and the table into README.md between its markers, so that the README's figures are
the script's (tests/test_example_figures.py checks that they agree).
"""

import argparse
import csv
import math
import sys
from dataclasses import dataclass
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

ROOT = Path(__file__).resolve().parents[2]
FMU = ROOT / "build" / "fmus" / "flexible_arm_hub.fmu"
OUT = ROOT / "build" / "examples" / "flexible_arm_pid"

# The arm as a rigid bar: m = rho A L = 1.616 kg, m L^2 / 3 = 34.47 kg m^2 about the hub, plus the
# rotor's 5 kg m^2. Its first bending mode, clamped at the hub, is at 2.909 rad/s (period 2.16 s).
LENGTH = 8.0
ROTOR = 5.0
INERTIA = 2767.0 * 7.299e-5 * LENGTH * LENGTH**2 / 3 + ROTOR
FIRST_BENDING = 2.909
# A run whose hub angle leaves this band (rad) has diverged; it is stopped there.
DIVERGED = 10.0


@dataclass(frozen=True)
class Move:
    """Rest-to-rest hub move from 0 to `angle` in `duration` seconds along the quintic
    s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 (zero speed and acceleration at both ends)."""

    angle: float = 1.0
    duration: float = 4.0

    def __call__(self, t):
        """Reference angle and speed at t."""
        tau = min(max(t / self.duration, 0.0), 1.0)
        s = tau**3 * (10 - 15 * tau + 6 * tau**2)
        ds = 30 * tau**2 * (1 - tau) ** 2 / self.duration
        return self.angle * s, self.angle * ds


@dataclass(frozen=True)
class Gains:
    """u = kp e + ki int(e) + kd de/dt, e = reference - hub angle; de/dt from the measured hub
    speed and the reference speed (no numerical differentiation). The defaults place the rigid
    arm's closed-loop poles at s = -2.5 rad/s (triple): kp = 3 J w^2, ki = J w^3, kd = 3 J w.
    The torque is held over a communication step h: the loop stays stable while kd h is well
    below 2 J_rotor (measured on this unit: 4 x the default kd at h = 0.01 s diverges)."""

    kp: float = 3 * INERTIA * 2.5**2
    ki: float = INERTIA * 2.5**3
    kd: float = 3 * INERTIA * 2.5

    def scaled(self, factor):
        return Gains(self.kp * factor, self.ki * factor, self.kd * factor)


OFF = Gains(0.0, 0.0, 0.0)


def simulate(fmu_path=FMU, move=Move(), gains=Gains(), stop=10.0, step=1e-2, unzipdir=None):
    """Runs the closed loop from rest to `stop` with communication step `step`; returns a dict of
    lists: time, reference, angle, speed, torque, tip (deflection, m). A diverged run (hub angle
    beyond DIVERGED) ends there."""
    md = read_model_description(fmu_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipdir = extract(fmu_path, unzipdir=unzipdir)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="arm")
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        measured = [vr["hub.angle"], vr["hub.speed"], vr["beam.tip.deflection"]]
        torque_vr = [vr["hub.drive.torque"]]
        rows = {k: [] for k in ("time", "reference", "angle", "speed", "torque", "tip")}
        integral = 0.0
        n = int(round(stop / step))
        for k in range(n + 1):
            t = k * step
            angle, speed, tip = fmu.getReal(measured)
            ref, ref_speed = move(t)
            error = ref - angle
            torque = gains.kp * error + gains.ki * integral + gains.kd * (ref_speed - speed)
            for key, value in zip(rows, (t, ref, angle, speed, torque, tip)):
                rows[key].append(value)
            if k == n or abs(angle) > DIVERGED:
                break
            fmu.setReal(torque_vr, [torque])
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=step)
            integral += error * step
        fmu.terminate()
    finally:
        fmu.freeInstance()
        fmu.freeLibrary()
    return rows


def rigid_tracking_error(gains=Gains(), move=Move(), stop=10.0, step=1e-2, substeps=100):
    """The largest tracking error of the same sampled loop on a rigid arm of inertia INERTIA (the
    controller's design model), integrated exactly enough in `substeps` per communication step."""
    angle = speed = integral = worst = 0.0
    for k in range(int(round(stop / step))):
        ref, ref_speed = move(k * step)
        error = ref - angle
        worst = max(worst, abs(error))
        torque = gains.kp * error + gains.ki * integral + gains.kd * (ref_speed - speed)
        for _ in range(substeps):
            speed += torque / INERTIA * step / substeps
            angle += speed * step / substeps
        integral += error * step
    return worst


def figures(rows, move):
    """Figures of merit: the largest and RMS tracking error over the run, the peak tip deflection,
    the residual vibration (largest |tip deflection| once the move has ended plus one period of
    the first bending mode, so the transient of the stop is excluded) and the final angle error."""
    settle = move.duration + 2 * math.pi / FIRST_BENDING
    errors = [r - a for r, a in zip(rows["reference"], rows["angle"])]
    after = [abs(d) for t, d in zip(rows["time"], rows["tip"]) if t >= settle]
    return {
        "completed": rows["time"][-1],
        "max_tracking_error": max(abs(e) for e in errors),
        "rms_tracking_error": math.sqrt(sum(e * e for e in errors) / len(errors)),
        "final_angle_error": abs(errors[-1]),
        "peak_tip_deflection": max(abs(d) for d in rows["tip"]),
        "residual_tip_deflection": max(after) if after else float("nan"),
        "peak_torque": max(abs(u) for u in rows["torque"]),
    }


HERE = Path(__file__).resolve().parent
README = HERE / "README.md"
TABLE_CSV = HERE / "arm_pid_table.csv"
BEGIN = "<!-- generated by arm_pid.py --table: the table below; do not edit by hand -->"
END = "<!-- end of the table generated by arm_pid.py --table -->"
# The README's runs: (label, gain scale, move duration, stop), all 1 rad at 10 ms steps.
CASES = [
    ("default gains, 1 rad in 4 s", 1.0, 4.0, 10.0),
    ("gains × 0.25", 0.25, 4.0, 10.0),
    ("gains × 2", 2.0, 4.0, 10.0),
    ("default gains, 1 rad in 8 s (14 s run)", 1.0, 8.0, 14.0),
    ("no controller", 0.0, 4.0, 10.0),
]
TABLE_FIELDS = ["case", "completed", "max_tracking_error", "rms_tracking_error", "final_angle_error",
                "peak_tip_deflection", "residual_tip_deflection", "peak_torque", "rigid_max_tracking_error"]


def case_figures(case, fmu_path=FMU, step=1e-2):
    """The figures of one of CASES, with the rigid design model's error."""
    label, scale, duration, stop = case
    move, gains = Move(1.0, duration), Gains().scaled(scale)
    f = figures(simulate(fmu_path, move, gains, stop, step), move)
    return dict(case=label, **f, rigid_max_tracking_error=rigid_tracking_error(gains, move, stop, step))


def table(rows):
    """The README's table (markdown lines) of the CASES' figures."""
    lines = ["| run (10 ms steps) | max \\|error\\| (rad) | RMS error (rad) | rigid-arm model, max error "
             "| peak tip deflection | residual tip vibration¹ |", "|---|---|---|---|---|---|"]
    for r in rows:
        if r["peak_torque"] == 0.0:  # no controller: the arm stays where it is
            lines.append(f"| {r['case']} | {r['max_tracking_error']:.3g} (the arm stays at 0) | | | "
                         f"{r['peak_tip_deflection']:.3g} | {r['residual_tip_deflection']:.3g} |")
            continue
        lines.append(f"| {r['case']} | {r['max_tracking_error']:.3g} | {r['rms_tracking_error']:.3g} | "
                     f"{r['rigid_max_tracking_error']:.3g} | {r['peak_tip_deflection']:.3f} m | "
                     f"{r['residual_tip_deflection']:.3f} m |")
    return lines


def read_table(path=TABLE_CSV):
    with open(path, newline="") as f:
        return [{k: (v if k == "case" else float(v)) for k, v in r.items()} for r in csv.DictReader(f)]


def readme_table(text):
    """The lines between the README's markers."""
    return text.split(BEGIN, 1)[1].split(END, 1)[0].strip().splitlines()


def write_table(fmu_path=FMU):
    rows = [case_figures(c, fmu_path) for c in CASES]
    with open(TABLE_CSV, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=TABLE_FIELDS)
        w.writeheader()
        w.writerows({k: (v if k == "case" else repr(float(v))) for k, v in r.items()} for r in rows)
    text = README.read_text()
    head, rest = text.split(BEGIN, 1)
    README.write_text(head + BEGIN + "\n" + "\n".join(table(rows)) + "\n" + END + rest.split(END, 1)[1])
    print("\n".join(table(rows)))
    print(f"wrote {TABLE_CSV} and the table into {README}")


def write_csv(rows, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time", "reference", "hub.angle", "hub.speed", "hub.drive.torque", "beam.tip.deflection"])
        for row in zip(*rows.values()):
            w.writerow([repr(x) for x in row])


def plot(rows, path, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = rows["time"]
    fig, ax = plt.subplots(3, 1, sharex=True, figsize=(8, 7.5))
    ax[0].plot(t, rows["reference"], "k--", label="reference")
    ax[0].plot(t, rows["angle"], label="hub angle")
    ax[0].set_ylabel("angle (rad)")
    ax[0].legend()
    err = ax[0].twinx()
    err.plot(t, [(r - a) * 1e3 for r, a in zip(rows["reference"], rows["angle"])], "C3", lw=0.8)
    err.set_ylabel("error (mrad)", color="C3")
    ax[1].plot(t, rows["torque"], "C1")
    ax[1].set_ylabel("hub torque (N m)")
    ax[2].plot(t, [d * 1e3 for d in rows["tip"]], "C2")
    ax[2].set_ylabel("tip deflection (mm)")
    ax[2].set_xlabel("time (s)")
    for a in ax:
        a.grid(alpha=0.3)
    ax[0].set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--fmu", type=Path, default=FMU)
    p.add_argument("-o", "--output", type=Path, default=OUT)
    p.add_argument("--angle", type=float, default=1.0, help="move amplitude (rad)")
    p.add_argument("--duration", type=float, default=4.0, help="move duration (s)")
    p.add_argument("--stop", type=float, default=10.0, help="end of the run (s)")
    p.add_argument("--step", type=float, default=1e-2, help="communication step (s)")
    p.add_argument("--gain-scale", type=float, default=1.0, help="multiplies kp, ki, kd")
    p.add_argument("--table", action="store_true", help="run the README's cases and write its table")
    a = p.parse_args(argv)
    if not a.fmu.is_file():
        sys.exit(f"{a.fmu} does not exist: run `make fmus` first")
    if a.table:
        write_table(a.fmu)
        return
    move, gains = Move(a.angle, a.duration), Gains().scaled(a.gain_scale)
    rows = simulate(a.fmu, move, gains, a.stop, a.step)
    a.output.mkdir(parents=True, exist_ok=True)
    write_csv(rows, a.output / "arm_pid.csv")
    f = figures(rows, move)
    plot(rows, a.output / "arm_pid.png",
         f"Flexible arm, PID (kp = {gains.kp:.0f}, ki = {gains.ki:.0f}, kd = {gains.kd:.0f}), "
         f"{a.angle} rad in {a.duration} s")
    print(f"gains: kp = {gains.kp:.1f} N m/rad, ki = {gains.ki:.1f} N m/(rad s), kd = {gains.kd:.1f} N m s/rad")
    for k, v in f.items():
        print(f"{k}: {v:.4g}")
    print(f"max_tracking_error of the rigid design model: {rigid_tracking_error(gains, move, a.stop, a.step):.4g}")
    print(f"wrote {a.output / 'arm_pid.csv'} and {a.output / 'arm_pid.png'}")


if __name__ == "__main__":
    main()
