"""Every packaged FMU is a valid FMI 2.0 co-simulation unit: fmpy's validator finds no problem,
and fmpy's own master runs it to its DefaultExperiment stop time with finite outputs."""

import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from conftest import packaged_fmus

FMUS = packaged_fmus()
IDS = [p.stem for p in FMUS]

# Simulated seconds above which a smoke run stops at start + SHORT_RUN instead.
LONG_RUN = 5.0
SHORT_RUN = 0.1


def test_there_are_packaged_fmus(fmu_dir):
    assert FMUS, f"no FMUs in {fmu_dir}: run `make fmus`"


@pytest.mark.parametrize("path", FMUS, ids=IDS)
def test_validate_fmu_finds_no_problem(path):
    assert validate_fmu(str(path)) == []


@pytest.mark.parametrize("path", FMUS, ids=IDS)
def test_the_zip_keeps_to_the_standard_and_stores_the_engines(path):
    """FMI's rules for the archive (compression 8, deflate, or 0, store; the data-descriptor bit
    only on deflated entries; version needed to extract at most 2.0; no encryption), and the
    engines stored: fmpy extracts the whole unit on every simulate_fmu call
    (fmu-harness/src/archive.rs)."""
    with zipfile.ZipFile(path) as z:
        for info in z.infolist():
            assert info.compress_type in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED), info
            assert not info.flag_bits & 0x1, info  # encrypted
            if info.compress_type == zipfile.ZIP_STORED:
                assert not info.flag_bits & 0x8, info
            assert info.extract_version <= 20, info
            binary = info.filename.startswith("binaries/")
            assert (info.compress_type == zipfile.ZIP_STORED) == binary, info


@pytest.mark.parametrize("path", FMUS, ids=IDS)
def test_simulates_to_the_default_stop_time_with_finite_outputs(path):
    md = read_model_description(path)
    ex = md.defaultExperiment
    start = float(ex.startTime or 0.0)
    stop = float(ex.stopTime)
    if stop - start > LONG_RUN:
        stop = start + SHORT_RUN
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    result = simulate_fmu(
        str(path),
        start_time=start,
        stop_time=stop,
        output_interval=float(ex.stepSize),
        output=outputs,
    )
    assert result["time"][-1] == pytest.approx(stop)
    assert len(result) == pytest.approx((stop - start) / float(ex.stepSize) + 1, abs=1)
    for name in outputs:
        assert np.all(np.isfinite(result[name].astype(float))), name
