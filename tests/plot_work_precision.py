"""Work-precision charts of `fmu-bench work-precision` (run by `make bench`): per case, the
relative error of its main output against the CPU time of one run, log-log, one colour per
formulation (circles and solid lines: error control over the tolerance; squares and dashed
lines: fixed step). Reads build/bench/points.csv, writes build/bench/<case>.png; with
--readme CASE FILE also a small copy of that case's chart for the README (docs/)."""
import argparse
import csv
import math
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def read(src):
    """{case: {formulation: {mode: [(cpu, error, setting)]}}} and each case's main output."""
    cases = defaultdict(lambda: defaultdict(lambda: defaultdict(list)))
    outputs = {}
    with open(src) as f:
        for row in csv.DictReader(f):
            if row["kind"] != "sweep" or row["status"] != "ok":
                continue
            err, cpu = float(row["error_relative"]), float(row["cpu_seconds_median"])
            if math.isnan(err) or err <= 0 or cpu <= 0:
                continue
            cases[row["case"]][row["formulation"]][row["mode"]].append((cpu, err, float(row["setting"])))
            outputs[row["case"]] = row["output"]
    return cases, outputs


def chart(case, formulations, output, path, small=False):
    fig, ax = plt.subplots(figsize=(6.4, 5.2) if small else (8, 6.5))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (name, modes) in enumerate(formulations.items()):
        color = colors[i % len(colors)]
        for mode, style in (("adaptive", "o-"), ("fixed", "s--")):
            pts = sorted(modes.get(mode, []), key=lambda p: -p[2])  # loose to tight
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, color=color, ms=4,
                          lw=1.2, label=f"{name}, {'error control' if mode == 'adaptive' else 'fixed step'}")
    ax.set_xlabel("CPU time of one run (s, median, one thread)")
    ax.set_ylabel(f"max |error| / max |reference| of {output}")
    ax.set_title(f"{case}: work-precision, every formulation against one reference")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6 if small else 7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    fig.tight_layout()
    fig.savefig(path, dpi=80 if small else 110)
    plt.close(fig)
    print(f"wrote {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", nargs="?", default=ROOT / "build" / "bench" / "points.csv", type=Path)
    ap.add_argument("--readme", nargs=2, metavar=("CASE", "FILE"),
                    help="also write a small chart of CASE to FILE")
    a = ap.parse_args()
    cases, outputs = read(a.csv)
    for case, formulations in sorted(cases.items()):
        chart(case, formulations, outputs[case], a.csv.parent / f"{case}.png")
    if a.readme:
        case, path = a.readme
        if case not in cases:
            raise SystemExit(f"{a.csv}: no points of case {case}")
        chart(case, cases[case], outputs[case], Path(path), small=True)


if __name__ == "__main__":
    main()
