"""The Linux binaries we ship load on glibc 2.28 (RHEL 8, Debian 10, Ubuntu 20.04 have 2.28-2.31):
every FMU's binaries/linux64 engine, and the wheel's engine and extension module, ask for no
glibc symbol version above 2.28. A plain link on the build machine (Debian 12, glibc 2.36) binds
exp, pow, hypot, log and the pthread keys to 2.29-2.35 versions, which an older loader refuses
("version `GLIBC_2.34' not found"); the Makefile links them through zig against glibc 2.28's
(LINKER). The versions come from the binary's own version references (`objdump -p`, binutils,
installed with gcc by `make test-tools`)."""

import os
import re
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest

from conftest import packaged_fmus

OLDEST_GLIBC = (2, 28)


def glibc_versions(binary):
    """The glibc versions the ELF file asks for (its version references), as (major, minor)."""
    objdump = shutil.which("objdump")
    if objdump is None:
        pytest.fail("objdump (binutils) is not installed: run `make test-tools`")
    dump = subprocess.run([objdump, "-p", str(binary)], capture_output=True, text=True, check=True).stdout
    references = dump.split("Version References:", 1)
    assert len(references) == 2, f"{binary}: no version references (not a dynamic ELF file?)"
    return {(int(a), int(b)) for a, b in re.findall(r"\bGLIBC_(\d+)\.(\d+)", references[1])}


def assert_portable(binary):
    versions = glibc_versions(binary)
    assert versions, f"{binary}: asks for no glibc version at all (not linked against glibc?)"
    newer = sorted(v for v in versions if v > OLDEST_GLIBC)
    assert not newer, (
        f"{binary} needs glibc {'.'.join(map(str, newer[-1]))}, newer than "
        f"{'.'.join(map(str, OLDEST_GLIBC))}: it was not linked through the Makefile's LINKER"
    )


def test_the_reader_sees_newer_versions():
    """A control of the reader: a program this system's own toolchain linked (/bin/ls) asks for
    GLIBC_2.2.5 (x86-64's first) and, on glibc 2.34 or newer, for 2.34 (__libc_start_main's), so
    a binary that asks for more than 2.28 cannot pass unseen."""
    system = tuple(int(x) for x in os.confstr("CS_GNU_LIBC_VERSION").split()[1].split(".")[:2])
    versions = glibc_versions("/bin/ls")
    assert (2, 2) in versions, versions
    if system >= (2, 34):
        assert (2, 34) in versions, versions
        with pytest.raises(AssertionError, match="newer than 2.28"):
            assert_portable("/bin/ls")


@pytest.mark.parametrize("fmu", packaged_fmus(), ids=lambda p: p.stem)
def test_fmu_engine_loads_on_glibc_2_28(fmu, tmp_path):
    with zipfile.ZipFile(fmu) as archive:
        names = [n for n in archive.namelist() if n.startswith("binaries/linux64/") and n.endswith(".so")]
        assert names, f"{fmu.name} carries no linux64 binary"
        for name in names:
            assert_portable(archive.extract(name, tmp_path))


def test_wheel_binaries_load_on_glibc_2_28():
    import fmu_beam  # the wheel `make wheel` installs into .venv

    package = Path(fmu_beam.__file__).parent
    binaries = sorted(package.glob("_native*.so")) + sorted((package / "engines" / "linux64").glob("*.so"))
    assert len(binaries) == 2, f"expected the extension module and the linux64 engine, found {binaries}"
    for binary in binaries:
        assert_portable(binary)
