"""Case C1 (planar paper §5.1, CASES.md): the packaged cantilever FMU driven by fmpy.

Checks the linearized frequencies printed by `fmu-harness modes`, the spectrum of the simulated
tip deflection, and energy conservation without damping.
"""
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu

ROOT = Path(__file__).resolve().parents[1]
FMU = ROOT / "build" / "fmus" / "cantilever_free_vibration.fmu"
SCENE = ROOT / "scenes" / "cantilever_free_vibration.toml"
HARNESS = ROOT / "target" / "release" / "fmu-harness"

# CASES.md, C1: consistent-mass Hermite FE model with N = 10 (Hz)
FE_N10 = [2.0854751, 13.069871, 36.604123, 71.779550, 118.84259]


def harness_modes(scene: Path, count: int = 5) -> list[float]:
    out = subprocess.run(
        [str(HARNESS), "modes", str(scene), "--count", str(count)],
        check=True, capture_output=True, text=True,
    ).stdout
    return [float(x) for x in re.findall(r"^mode\s+\d+:\s+([0-9.eE+-]+)\s+Hz", out, re.MULTILINE)]


def peak_frequency(signal: np.ndarray, dt: float, near: float) -> float:
    """Frequency of the spectral peak nearest `near`: Hann window, zero padding to 2^21
    points and parabolic interpolation of the log magnitude."""
    x = (signal - signal.mean()) * np.hanning(len(signal))
    nfft = 1 << 21
    mag = np.abs(np.fft.rfft(x, nfft))
    freqs = np.fft.rfftfreq(nfft, dt)
    band = np.where((freqs > 0.9 * near) & (freqs < 1.1 * near))[0]
    k = band[np.argmax(mag[band])]
    a, b, c = np.log(mag[k - 1 : k + 2])
    return freqs[k] + 0.5 * (a - c) / (a - 2 * b + c) * (freqs[1] - freqs[0])


def test_modes_match_fe_column_to_six_digits():
    got = harness_modes(SCENE)
    assert len(got) == 5, got
    for k, (f, ref) in enumerate(zip(got, FE_N10), start=1):
        assert f == pytest.approx(ref, rel=5e-7), f"mode {k}: {f} Hz vs FE {ref} Hz"


def test_spectrum_peaks_at_modes_1_and_2():
    dt = 1e-3
    res = simulate_fmu(str(FMU), stop_time=20.0, output_interval=dt, output=["beam.tip.deflection"])
    tip = res["beam.tip.deflection"]
    assert tip[0] == pytest.approx(0.01, rel=1e-12)
    for k in (0, 1):
        f = peak_frequency(tip, dt, FE_N10[k])
        rel = abs(f - FE_N10[k]) / FE_N10[k]
        print(f"mode {k + 1}: spectral peak {f:.6f} Hz, FE {FE_N10[k]} Hz, rel. diff {rel:.1e}")
        assert rel < 1e-3


def test_energy_after_100_periods_without_damping():
    period = 1.0 / FE_N10[0]
    stop = 100 * period
    res = simulate_fmu(
        str(FMU), stop_time=stop, output_interval=0.05,
        output=["energy.total", "energy.kinetic", "energy.strain"],
    )
    e0, e1 = res["energy.total"][0], res["energy.total"][-1]
    print(f"energy {e0:.9e} J at 0 s, {e1:.9e} J at {res['time'][-1]:.2f} s")
    # initial strain energy of the static tip-load shape: F δ / 2 with F = 3 E J δ / L^3
    ej = 72e9 * 0.01**4 / 12
    assert e0 == pytest.approx(0.5 * 3 * ej * 0.01 / 2.0**3 * 0.01, rel=1e-9)
    assert abs(e1 - e0) / e0 < 1e-3
    # the energy really moves between kinetic and strain: the test would see a frozen model
    assert res["energy.kinetic"].max() > 0.5 * e0
