"""The split slider-crank joined at the pin, driven from an fmpy script: the same interface-force
coupling as `fmu-harness cosim joint.toml` ([[joint]]), written with FMU2Slave and
getDirectionalDerivative, the way a user couples two of our units without our master.

Both units take the pin force as an input load (the crank λ, the rod −λ). In each communication
step the force at the step's end is iterated until the two pins coincide: the units get the force
as a ramp from its value at the step's start (fmi2SetRealInputDerivatives), step once, are compared
and restored (FMU state) for the next iterate; the Jacobian of the pin mismatch starts as
h²/4 (W_crank + W_rod), W the pin accelerations' derivatives with respect to the pin force
(getDirectionalDerivative), and is refined by Broyden's update. Steps land on the crank's torque
cut (`solver.next_event_time`), where the force jumps to the value that makes the pin
accelerations agree; a step in which a unit took internal substeps (`solver.steps`) is retried with
half the step.

    python joint_fmpy.py [--step 1e-3] [--stop 1.6] [--rho 2770] [-o build/split/joint_fmpy.csv]
"""

import argparse
import time
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

ROOT = Path(__file__).resolve().parents[2]
FMUS = ROOT / "build" / "fmus"
JACOBIAN_SCALE = 0.25   # h²/4: the step's position response per unit of mobility
TOLERANCE = 1e-9        # m, largest pin mismatch at the end of a step
MAX_ITERATIONS = 10
MAX_HALVINGS = 10


class Unit:
    """One FMU with the pin load `pin` (inputs pin.fx, pin.fy; outputs pin.x, pin.y, pin.ax,
    pin.ay) and the fmu-beam outputs solver.steps and solver.next_event_time."""

    def __init__(self, name, fmu, start, sign):
        md = read_model_description(fmu)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu),
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()
        for k, v in start.items():
            if isinstance(v, bool):
                self.fmu.setBoolean([self.vr[k]], [v])
            else:
                self.fmu.setReal([self.vr[k]], [v])
        self.sign = sign
        self.force = [self.vr["pin.fx"], self.vr["pin.fy"]]
        self.position = [self.vr["pin.x"], self.vr["pin.y"]]
        self.acceleration = [self.vr["pin.ax"], self.vr["pin.ay"]]
        self.state = None

    def mobility(self):
        """W = d(pin acceleration)/d(pin force), one directional derivative per force column."""
        cols = [self.fmu.getDirectionalDerivative(self.acceleration, [f], [1.0]) for f in self.force]
        return np.array(cols).T

    def set_force(self, value, slope=None):
        self.fmu.setReal(self.force, list(self.sign * value))
        rate = np.zeros(2) if slope is None else self.sign * slope
        self.fmu.setRealInputDerivatives(self.force, [1, 1], list(rate))

    def real(self, refs):
        return np.array(self.fmu.getReal(refs))

    def steps(self):
        return self.fmu.getInteger([self.vr["solver.steps"]])[0]


def is_close(a, b):
    return a == b or abs(a - b) <= 1e-9 * max(abs(a), abs(b))


def run(step, stop, rho):
    start = {"solver.adaptive": False, "solver.max_step": step}
    crank = Unit("crank", FMUS / "slider_crank_split_crank.fmu", {"crank.rho": rho, **start}, 1.0)
    rod = Unit("rod", FMUS / "slider_crank_split_rod_force.fmu", start, -1.0)
    units = [crank, rod]
    for u in units:
        u.fmu.setupExperiment(startTime=0.0, stopTime=stop)
        u.fmu.enterInitializationMode()
        u.fmu.exitInitializationMode()

    def residual(refs):          # Σ ± (pin quantity) over both units
        return sum(u.sign * u.real(refs(u)) for u in units)

    def mobility():              # Σ ± W ±
        return sum(u.mobility() for u in units)

    def consistent(lam):         # the force that makes the pin accelerations agree, exact
        for u in units:
            u.set_force(lam)
        lam = lam - np.linalg.solve(mobility(), residual(lambda u: u.acceleration))
        for u in units:
            u.set_force(lam)
        return lam

    def save():
        for u in units:
            u.state = u.fmu.getFMUstate()

    def restore():
        for u in units:
            u.fmu.setFMUstate(u.state)

    lam, previous, jacobian = consistent(np.zeros(2)), None, None
    stats = dict(iterations=0, restores=0, refusals=0, unit_steps=0, steps=0)

    def coupled_step(t, h):
        """The joint iteration of one step; True when accepted."""
        nonlocal lam, previous, jacobian
        end = lam.copy() if previous is None else lam + (lam - previous[0]) * (h / previous[1])
        if jacobian is None:
            jac = mobility() * (JACOBIAN_SCALE * h * h)
        else:
            jac = jacobian[0] * (h / jacobian[1]) ** 2
        counts = [u.steps() for u in units]
        last = None
        for k in range(MAX_ITERATIONS):
            if k > 0:
                restore()
                stats["restores"] += 1
            slope = (end - lam) / h
            for u in units:
                u.set_force(lam, slope)
            stats["iterations"] += 1
            for u in units:
                u.fmu.doStep(t, h)
            stats["unit_steps"] += len(units)
            if any(u.steps() != c + 1 for u, c in zip(units, counts)):
                break        # internal substeps saw the force inside the step: refuse
            r = residual(lambda u: u.position)
            if last is not None:                     # Broyden's rank-one update
                dl = end - last[0]
                if dl @ dl > 0:
                    jac = jac + np.outer((r - last[1]) - jac @ dl, dl) / (dl @ dl)
            if np.abs(r).max() <= TOLERANCE:
                previous, lam, jacobian = (lam, h), end, (jac, h)
                return True
            last = (end.copy(), r)
            end = end - np.linalg.solve(jac, r)
        stats["refusals"] += 1
        jacobian, previous = None, None
        return False

    rows, t, grid = [], 0.0, 0

    def record():
        rows.append([t, *crank.real([crank.vr["crank.tip.x"], crank.vr["crank.tip.y"]]),
                     rod.real([rod.vr["slider.position"]])[0], *crank.real(crank.force)])

    record()
    while not (t > stop or is_close(t, stop)):
        target = (grid + 1) * step
        target = stop if target > stop or is_close(target, stop) else target
        h = min(target - t, step)
        for halvings in range(MAX_HALVINGS + 1):
            event = min(u.real([u.vr["solver.next_event_time"]])[0] for u in units)
            if t < event < t + h and not is_close(event, t + h):
                h = event - t
            on_event = is_close(t + h, event)
            save()
            if coupled_step(t, h):
                break
            restore()
            h /= 2
        else:
            raise RuntimeError(f"the step at t = {t} was refused {MAX_HALVINGS} times")
        t += h
        stats["steps"] += 1
        if is_close(t, target):
            t, grid = target, grid + 1
        if on_event:
            lam, previous, jacobian = consistent(lam), None, None
        if t == target:
            record()
    for u in units:
        u.fmu.terminate()
        u.fmu.freeInstance()
    return np.array(rows), stats


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--step", type=float, default=1e-3)
    ap.add_argument("--stop", type=float, default=1.6)
    ap.add_argument("--rho", type=float, default=2770.0, help="crank density (C3: 2770)")
    ap.add_argument("-o", "--output", type=Path, default=ROOT / "build" / "split" / "joint_fmpy.csv")
    a = ap.parse_args()
    cpu = time.process_time()
    rows, stats = run(a.step, a.stop, a.rho)
    cpu = time.process_time() - cpu
    a.output.parent.mkdir(parents=True, exist_ok=True)
    header = "time,crank.crank.tip.x,crank.crank.tip.y,rod.slider.position,crank.pin.fx,crank.pin.fy"
    np.savetxt(a.output, rows, delimiter=",", header=header, comments="", fmt="%.17g")
    n = stats["steps"]
    print(f"{n} steps, {stats['iterations'] / n:.2f} iterations, {stats['restores'] / n:.2f} restores "
          f"and {stats['unit_steps'] / n:.2f} unit steps per step, {stats['refusals']} refused; "
          f"CPU {cpu:.2f} s; wrote {a.output}")


if __name__ == "__main__":
    main()
