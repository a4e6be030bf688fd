"""Demo of case C1 (free vibration of a clamped beam): simulate the packaged FMU with fmpy, write
the tip deflection to CSV, and plot it with its amplitude spectrum against the FE natural
frequencies that `fmu-harness modes` reports.

Writes build/demo/cantilever_free_vibration.csv and .png. Run by `make demo`.
"""

import argparse
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import read_model_description, simulate_fmu  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fmu_util import C1, ROOT, harness_modes  # noqa: E402

OUTPUT = "beam.tip.deflection"
MODES_SHOWN = 5


def amplitude_spectrum(t, x, pad=8):
    """One-sided amplitude spectrum of x(t): mean removed, Hann window, zero-padded FFT."""
    dt = t[1] - t[0]
    w = np.hanning(len(x))
    n = pad * (1 << int(np.ceil(np.log2(len(x)))))
    spec = np.fft.rfft((x - x.mean()) * w, n)
    freq = np.fft.rfftfreq(n, dt)
    return freq, 2.0 * np.abs(spec) / w.sum()


def peak_near(freq, amp, f0, half_width):
    """The frequency of the largest amplitude within f0 ± half_width."""
    band = (freq > f0 - half_width) & (freq < f0 + half_width)
    return freq[band][np.argmax(amp[band])]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fmu", type=Path, default=ROOT / "build" / "fmus" / f"{C1}.fmu")
    ap.add_argument("--scene", type=Path, default=ROOT / "scenes" / f"{C1}.toml")
    ap.add_argument("--harness", type=Path, default=ROOT / "target" / "release" / "fmu-harness")
    ap.add_argument("--stop-time", type=float, default=20.0,
                    help="simulated seconds (default 20: a spectrum resolution of 0.05 Hz)")
    ap.add_argument("--out", type=Path, default=ROOT / "build" / "demo")
    args = ap.parse_args()

    md = read_model_description(args.fmu)
    step = float(md.defaultExperiment.stepSize)
    fe = harness_modes(args.harness, args.scene, count=MODES_SHOWN)

    result = simulate_fmu(str(args.fmu), stop_time=args.stop_time, output_interval=step, output=[OUTPUT])
    t, x = result["time"], result[OUTPUT]

    args.out.mkdir(parents=True, exist_ok=True)
    csv_path, png_path = args.out / f"{C1}.csv", args.out / f"{C1}.png"
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time", OUTPUT])
        w.writerows((repr(float(a)), repr(float(b))) for a, b in zip(t, x))

    freq, amp = amplitude_spectrum(t, x)
    resolution = 1.0 / (t[-1] - t[0])
    print(f"{C1}: {len(t)} samples, {t[-1] - t[0]:g} s, spectrum resolution {resolution:.3g} Hz")
    for k, f0 in enumerate(fe[:2], start=1):
        fp = peak_near(freq, amp, f0, max(2 * resolution, 0.05 * f0))
        print(f"  mode {k}: FE {f0:.7g} Hz, spectral peak {fp:.7g} Hz (difference {fp - f0:+.3g} Hz)")

    fig, (ax_t, ax_f) = plt.subplots(2, 1, figsize=(9, 7), constrained_layout=True)
    ax_t.plot(t, x * 1e3, lw=0.8)
    ax_t.set_xlabel("time (s)")
    ax_t.set_ylabel("tip deflection (mm)")
    ax_t.set_title(f"C1: clamped aluminium beam released from a {x[0] * 1e3:.3g} mm tip displacement")
    ax_t.grid(alpha=0.3)
    fmax = 1.25 * fe[-1]
    shown = freq <= fmax
    ax_f.semilogy(freq[shown], np.maximum(amp[shown], 1e-16) * 1e3, lw=0.8, label="FMU tip deflection")
    for k, f0 in enumerate(fe, start=1):
        ax_f.axvline(f0, color="C3", ls="--", lw=0.8, label="FE natural frequencies" if k == 1 else None)
    ax_f.set_xlim(0, fmax)
    top = ax_f.secondary_xaxis("top")
    top.set_xticks(fe, [f"{f0:.4g}" for f0 in fe], fontsize=8, color="C3")
    peak = amp[shown].max() * 1e3
    ax_f.set_ylim(peak * 1e-9, peak * 5)
    ax_f.set_xlabel("frequency (Hz)")
    ax_f.set_ylabel("amplitude (mm)")
    ax_f.set_title("amplitude spectrum (Hann window, zero-padded FFT); FE frequencies in Hz above")
    ax_f.grid(alpha=0.3, which="both")
    # between the 4th and 5th lines, clear of the peaks
    ax_f.legend(loc="upper left", bbox_to_anchor=(fe[3] / fmax + 0.02, 0.98))
    fig.savefig(png_path, dpi=130)
    print(f"wrote {csv_path.relative_to(ROOT) if csv_path.is_relative_to(ROOT) else csv_path}")
    print(f"wrote {png_path.relative_to(ROOT) if png_path.is_relative_to(ROOT) else png_path}")


if __name__ == "__main__":
    main()
