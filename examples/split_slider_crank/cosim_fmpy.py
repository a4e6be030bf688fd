"""The split slider-crank coupled by an fmpy script (FMU2Slave), the same calls as
`fmu-harness cosim system.toml`: Gauss-Seidel, crank first with the pin force held, then the rod
with the crank tip position interpolated by the parabola through the last two communication points
and the new one (fmi2SetRealInputDerivatives, orders 1 and 2).

    python cosim_fmpy.py [--step 1e-3] [--stop 0.3] [--rho 55400] [-o out.csv]
"""

import argparse
import csv
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

ROOT = Path(__file__).resolve().parents[2]
FMUS = ROOT / "build" / "fmus"


class Unit:
    def __init__(self, path, name, start):
        self.md = read_model_description(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.dir = extract(path)
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier,
                             instanceName=name)
        self.fmu.instantiate(loggingOn=False)
        for k, v in start.items():
            self.fmu.setReal([self.vr[k]], [v])

    def init(self, start, stop):
        self.fmu.setupExperiment(startTime=start, stopTime=stop)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def get(self, name):
        return self.fmu.getReal([self.vr[name]])[0]

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def parabola_derivatives(points, t):
    """First and second derivative at t of the polynomial through up to three (t, value) points
    (Newton divided differences, as fmu-harness/src/cosim/extrapolation.rs)."""
    if len(points) == 1:
        return 0.0, 0.0
    (ta, a), (tb, b) = points[0], points[1]
    ab = (b - a) / (tb - ta)
    if len(points) == 2:
        return ab, 0.0
    tc, c = points[2]
    bc = (c - b) / (tc - tb)
    c2 = (bc - ab) / (tc - ta)
    return ab + c2 * (2.0 * t - ta - tb), 2.0 * c2


POSITION = [("crank.tip.x", "pin_x.drive.position"), ("crank.tip.y", "pin_y.drive.position")]
FORCE = [("pin_x.force", "pin.fx"), ("pin_y.force", "pin.fy")]
OUTPUTS = [("crank", "crank.tip.x"), ("crank", "crank.tip.y"), ("rod", "slider.position"),
           ("rod", "pin_x.force"), ("rod", "pin_y.force")]


def run(step=1e-3, stop=0.3, rho=55400.0, fmu_dir=FMUS):
    """Rows [t, crank tip x, y, slider position, pin forces] at every communication point."""
    crank = Unit(fmu_dir / "slider_crank_split_crank.fmu", "crank", {"crank.rho": rho})
    rod = Unit(fmu_dir / "slider_crank_split_rod.fmu", "rod", {})
    units = {"crank": crank, "rod": rod}
    try:
        crank.init(0.0, stop)
        rod.init(0.0, stop)
        pos = [[(0.0, crank.get(src))] for src, _ in POSITION]
        force = [[(0.0, -rod.get(src))] for src, _ in FORCE]
        for hist, (_, dst) in zip(pos, POSITION):
            rod.fmu.setReal([rod.vr[dst]], [hist[-1][1]])
        for hist, (_, dst) in zip(force, FORCE):
            crank.fmu.setReal([crank.vr[dst]], [hist[-1][1]])
        rows = [[0.0] + [units[u].get(n) for u, n in OUTPUTS]]
        t, n = 0.0, 0
        while not (t > stop or abs(t - stop) <= 1e-9 * max(abs(t), abs(stop))):
            target = min((n + 1) * step, stop)
            if abs(target - stop) <= 1e-9 * stop:
                target = stop
            h = target - t
            crank.fmu.setReal([crank.vr[d] for _, d in FORCE], [f[-1][1] for f in force])
            crank.fmu.doStep(t, h)
            new = [crank.get(src) for src, _ in POSITION]
            vrs, ders = [], []
            for hist, (_, dst), y in zip(pos, POSITION, new):
                d1, d2 = parabola_derivatives(hist[-2:] + [(t + h, y)], t)
                vrs += [rod.vr[dst]] * 2
                ders += [d1, d2]
            rod.fmu.setReal([rod.vr[d] for _, d in POSITION], [p[-1][1] for p in pos])
            rod.fmu.setRealInputDerivatives(vrs, [1, 2, 1, 2], ders)
            rod.fmu.doStep(t, h)
            t, n = target, n + 1
            for hist, y in zip(pos, new):
                hist.append((t, y))
                del hist[:-3]
            for hist, (src, _) in zip(force, FORCE):
                hist.append((t, -rod.get(src)))
                del hist[:-3]
            rows.append([t] + [units[u].get(nm) for u, nm in OUTPUTS])
        return rows
    finally:
        crank.close()
        rod.close()


def header():
    return ["time"] + [f"{u}.{n}" for u, n in OUTPUTS]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--step", type=float, default=1e-3)
    ap.add_argument("--stop", type=float, default=0.3)
    ap.add_argument("--rho", type=float, default=55400.0, help="crank density (C3: 2770)")
    ap.add_argument("-o", "--output", type=Path, default=ROOT / "build" / "split" / "fmpy.csv")
    a = ap.parse_args()
    rows = run(a.step, a.stop, a.rho)
    a.output.parent.mkdir(parents=True, exist_ok=True)
    with open(a.output, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header())
        w.writerows([[repr(x) for x in r] for r in rows])
    print(f"wrote {a.output} ({len(rows)} rows)")


if __name__ == "__main__":
    main()
