"""Fixtures of the FMU tests: where the packaged FMUs (build/fmus/, from `make fmus`) and the
harness binary are, and C1 instances driven through fmpy as a user of the FMU would."""

import os
import subprocess
from pathlib import Path

import pytest
from fmpy import extract, read_model_description

from fmu_util import C1, ROOT, Instance

FMU_DIR = Path(os.environ.get("FMU_DIR", ROOT / "build" / "fmus"))
HARNESS = Path(os.environ.get("FMU_HARNESS", ROOT / "target" / "release" / "fmu-harness"))


def packaged_fmus():
    """Every packaged FMU, sorted (parametrizes tests at collection time)."""
    return sorted(FMU_DIR.glob("*.fmu"))


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def fmu_dir():
    if not FMU_DIR.is_dir():
        pytest.fail(f"{FMU_DIR} does not exist: run `make fmus` first")
    return FMU_DIR


@pytest.fixture(scope="session")
def harness():
    if not HARNESS.is_file():
        pytest.fail(f"{HARNESS} does not exist: run `make release` first")
    return HARNESS


@pytest.fixture(scope="session")
def c1_fmu(fmu_dir):
    path = fmu_dir / f"{C1}.fmu"
    if not path.is_file():
        pytest.fail(f"{path} does not exist: run `make fmus` first")
    return path


@pytest.fixture(scope="session")
def c1_unzipped(c1_fmu, tmp_path_factory):
    """The C1 FMU extracted once per session, and its model description."""
    unzipdir = extract(c1_fmu, unzipdir=tmp_path_factory.mktemp("c1_unzipped"))
    return unzipdir, read_model_description(c1_fmu)


@pytest.fixture
def new_instance(c1_unzipped):
    """A factory of instantiated C1 FMUs; each is freed after the test."""
    made = []

    def make(name="instance", logging_on=True):
        inst = Instance(*c1_unzipped, name=name, logging_on=logging_on)
        made.append(inst)
        return inst

    yield make
    for inst in made:
        inst.close()


class Packaged:
    """{(scene, version): FMU path}: a shipped scene packaged as an FMI 2.0 or 3.0 unit with the
    release engine, on first use, once per session (both versions from one engine)."""

    def __init__(self, harness, out):
        self.harness, self.out, self.paths = harness, out, {}

    def __getitem__(self, key):
        scene, version = key
        if key not in self.paths:
            path = self.out / f"{scene}.v{version}.fmu"
            subprocess.run(
                [self.harness, "package", ROOT / "scenes" / f"{scene}.toml", "-o", path,
                 "--binary", ROOT / "target" / "release" / "libfmu_beam.so",
                 "--fmi-version", str(version)],
                check=True, capture_output=True,
            )
            self.paths[key] = path
        return self.paths[key]


@pytest.fixture(scope="session")
def packaged(tmp_path_factory, harness):
    """Shipped scenes as FMI 2.0 and 3.0 units: `packaged[scene, version]` is the FMU's path."""
    return Packaged(harness, tmp_path_factory.mktemp("units_by_version"))
