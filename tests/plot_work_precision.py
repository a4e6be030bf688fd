"""Work-precision chart of `fmu-harness work-precision` (run by `make bench`): relative error
of each case's main output against CPU time, log-log, one curve per integrator mode.
Reads build/bench/work_precision.csv, writes build/bench/work_precision.png."""
import csv
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
src = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "build" / "bench" / "work_precision.csv"
out = src.with_suffix(".png")

curves = defaultdict(list)
with open(src) as f:
    for row in csv.DictReader(f):
        curves[(row["case"], row["mode"])].append(
            (float(row["cpu_seconds_median"]), float(row["error_relative"]), float(row["setting"])))

cases = sorted({c for c, _ in curves})
fig, ax = plt.subplots(figsize=(8, 5.5))
colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
for i, case in enumerate(cases):
    for mode, style in (("adaptive", "o-"), ("fixed", "s--")):
        pts = sorted(curves.get((case, mode), []))
        if pts:
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, color=colors[i % len(colors)],
                      label=f"{case}, {'error control' if mode == 'adaptive' else 'fixed step'}", ms=4)
ax.set_xlabel("CPU time of one run (s, median of 3, one thread)")
ax.set_ylabel("max |error| / max |reference| of the main output")
ax.set_title("Work-precision: error against a tolerance-1e-9 reference vs. time")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7, ncol=2)
fig.tight_layout()
fig.savefig(out, dpi=110)
print(f"wrote {out}")
