"""A design study in a dozen lines: the tip droop of a rotor blade on a vertical shaft
(examples/blade_droop/blade.toml) over the hub speed and the blade's stiffness, with
fmu_beam.sweep on every local core, or on a Dask cluster.

    .venv/bin/python examples/blade_droop/droop_sweep.py                  # all local cores
    .venv/bin/python examples/blade_droop/droop_sweep.py --scheduler tcp://127.0.0.1:8786
    .venv/bin/python examples/blade_droop/droop_sweep.py --quick          # 2 speeds x 1 modulus

Writes DIR/droop.csv and DIR/droop.png (default DIR: build/examples/blade_droop). The plot draws
beside each curve the one-mode estimate of centrifugal stiffening, droop(Omega) = droop(0) /
(1 + S Omega^2 / omega_0^2) with Southwell's coefficient S = 1.193 of a cantilever's first flap
mode and omega_0 its frequency at rest, and at Omega = 0 the Euler-Bernoulli value q L^4 / (8 E I).
"""

import argparse
import math
from pathlib import Path

import fmu_beam

HERE = Path(__file__).resolve().parent
SCENE = HERE / "blade.toml"
ROOT = HERE.parents[1]
SPEEDS = [0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0]  # rad/s
MODULI = [3.5e10, 7e10, 14e10]  # Pa: half, nominal (aluminium) and twice
SOUTHWELL = 1.193  # first flap mode of a uniform cantilever, no hub radius


def droop(df):
    """The settled droop: minus the tip's height averaged over the last second (the blade's
    damping is 5 % at its flap frequency, so it has settled there)."""
    last = df[df.index >= df.index[-1] - 1.0]
    return {"droop": -last["blade.tip.z"].mean()}


def study(speeds, moduli, client=None, jobs=None, progress=True):
    scene = fmu_beam.Scene.load(SCENE)
    return fmu_beam.sweep(scene, {"shaft.drive.omega": speeds, "blade.E": moduli}, outputs=["blade.tip.z"],
                          reduce=droop, client=client, jobs=jobs, progress=progress)


def at_rest(E, scene=None):
    """Euler-Bernoulli: the static droop q L^4 / (8 E I) and the flap frequency (rad/s) of the
    scene's blade with modulus E."""
    b = (scene or fmu_beam.Scene.load(SCENE)).to_dict()["beam"][0]
    L, rho, A, I = b["length"], b["material"]["rho"], b["section"]["A"], b["section"]["Iy"]
    q = rho * A * 9.81
    return q * L**4 / (8 * E * I), 1.875**2 * math.sqrt(E * I / (rho * A * L**4))


def plot(df, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for k, (E, runs) in enumerate(df.groupby("blade.E")):
        color = f"C{k}"
        ax.plot(runs["shaft.drive.omega"], 1e3 * runs["droop"], "o-", color=color, label=f"E = {E / 1e9:.0f} GPa")
        d0, w0 = at_rest(E)
        w = np.linspace(0, max(df["shaft.drive.omega"]), 100)
        ax.plot(w, 1e3 * d0 / (1 + SOUTHWELL * w**2 / w0**2), "--", color=color, lw=0.8)
    ax.plot([], [], "k--", lw=0.8, label="one mode, Southwell S = 1.193")
    ax.set_xlabel("hub speed Omega (rad/s)")
    ax.set_ylabel("tip droop (mm)")
    ax.set_title("Rotor blade on a vertical shaft: droop under gravity")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scheduler", help="a dask.distributed scheduler's address (default: the local cores)")
    p.add_argument("--jobs", type=int, help="local processes (default: every core)")
    p.add_argument("--quick", action="store_true", help="2 speeds and 1 modulus")
    p.add_argument("-o", "--output", type=Path, default=ROOT / "build" / "examples" / "blade_droop")
    a = p.parse_args()
    speeds, moduli = ([0.0, 20.0], [7e10]) if a.quick else (SPEEDS, MODULI)
    client = None
    if a.scheduler:
        from distributed import Client

        client = Client(a.scheduler)
    df = study(speeds, moduli, client=client, jobs=a.jobs)
    a.output.mkdir(parents=True, exist_ok=True)
    df.to_csv(a.output / "droop.csv")
    plot(df, a.output / "droop.png")
    print(df.to_string())
    print(f"wrote {a.output / 'droop.csv'} and {a.output / 'droop.png'}")


if __name__ == "__main__":
    main()
