"""The Windows unit, run for real (issue 14). Every packaged FMU carries
binaries/win64/<id>.dll beside binaries/linux64/<id>.so. Our own C master (tests/c/fmu_run.c)
is built twice, with gcc and with mingw-w64; the gcc build drives the .so natively, the mingw
build drives the .dll under Wine, through the same call sequence: instantiate (with the
resources URI a Windows master gives, file:///Z:/...), initialize, step, read the outputs, take,
serialize, deserialize and set the FMU state and rerun from it, NaN into a Real, a negative
step, terminate, free. Then:

- each platform's reruns from its saved states repeat its first run bit for bit;
- the two platforms agree on every status, on the messages of the misuse, on the serialized
  state's size and on the communication times bit for bit, and on the outputs within the
  tolerances below;
- a state serialized by one platform's unit restores in the other's and runs on.

Tolerances (maximum over the run of |Windows - Linux|, relative to the output's largest
magnitude over the run, see `differences` for outputs that are zero by the physics). The two
binaries are the same Rust source built by two compilers (rustc 1.95 and 1.96) against two C
libraries: libm's sin, cos, exp, atan2 (glibc, mingw-w64's) may round differently in the last
bit, and LLVM may order operations differently. Last-bit differences can decide:
- with fixed steps (C1, C3 as shipped since issue 34): how many Newton iterations end a step, so
  the outputs may differ by a Newton correction left over (Newton stops within its tolerance;
  C3 at its fixed 6.25e-4 s and Newton tolerance 4e-9, 2 560 steps, differed by 1.5e-10 of the
  amplitude, 0.04 of the tolerance; at 3.71e-4 s and 1e-6, 4 313 steps, by 7.9e-11, with one
  Newton iteration more on Linux in 14 927): FIXED_RTOL = 0.1 x tolerance;
- with error control (C3, C6, the arm): also whether the error estimate (a difference of
  accelerations, weighted by the tolerance) accepts a step and how long the next one is, so the
  two runs may take different step sequences, each within the error the scene's tolerance
  allows: their difference is then of the order of either run's global error, a few times the
  local tolerance over hundreds of steps: ADAPTIVE_RTOL = 10 x tolerance.
Measured (Wine 8.0, rustc 1.96 for win64, 1.95 for linux64): C1 and C6 agree bit for bit,
the arm to 3e-9 of the amplitude (hub.speed), C3 to 9e-8 (crank_rod.speed, tolerance 1e-6,
error control, before issue 34),
with the same step, Newton and rejection counts on both; `WIN64_REPORT=1 pytest -s` prints the
figures per output.
Outputs named solver.* (counters, the constraint residual's rounding noise, the next event
time) are not compared as physics; the residual must stay below the tolerance on both.
"""

import os
import shutil
import struct
import subprocess
import zipfile
from pathlib import Path, PureWindowsPath

import pytest
from fmpy import extract, read_model_description, supported_platforms

from conftest import packaged_fmus
from fmu_util import ROOT

FMI2_ERROR = 3
WIN64_PACKAGES = ["rustc-web", "cargo-web", "rust-web-src", "gcc-mingw-w64-x86-64"]

# (scene, input driven before each step as amplitude * 4 s (1 - s), s = t / stop: vr name and
# amplitude), stop time (None: the scene's), communication step (None: the scene's)
CASES = [
    ("cantilever_free_vibration", None, None, None),  # C1: fixed steps
    ("slider_crank", None, None, None),  # C3: a fixed step, a closed loop
    ("pendulum_3d", None, None, None),  # C6: 3D beam and quaternions, error control
    ("flexible_arm", ("hub.drive.torque", 40.0), 2.0, None),  # an input: lands on each point
]
FIXED_RTOL = 0.1
ADAPTIVE_RTOL = 10.0
# an output below 1e-4 of the largest of its unit is zero by the physics: C3's rod tip held on
# the slide line (3.7e-7 m against 0.37 m) differed by 7e-16 m between the platforms after a
# state restore, round-off that a floor of 1e-6 made 1.9e-9 "relative" at its fixed step
FLOOR = 1e-4


def bits(hex16):
    return struct.unpack("<d", int(hex16, 16).to_bytes(8, "little"))[0]


def hex_bits(x):
    return int.from_bytes(struct.pack("<d", x), "little").to_bytes(8, "big").hex()


def windows_path(path):
    """The path Wine gives a Linux path (drive Z: is the root)."""
    return str(PureWindowsPath("Z:/") / PureWindowsPath(str(Path(path).resolve()).lstrip("/")))


def carries_win64(path):
    with zipfile.ZipFile(path) as z:
        return any(n.startswith("binaries/win64/") for n in z.namelist())


def win64_toolchain_installed():
    if not shutil.which("dpkg-query"):
        return False
    r = subprocess.run(["dpkg-query", "-W", "-f", "${Status}\n", *WIN64_PACKAGES], capture_output=True, text=True)
    return r.stdout.count("install ok installed") == len(WIN64_PACKAGES)


FMUS = packaged_fmus()
WIN64_FMUS = [p for p in FMUS if carries_win64(p)]


def test_every_fmu_carries_win64_when_the_toolchain_is_installed():
    """`make fmus` packages the Windows engine into every unit wherever it can be built."""
    if os.environ.get("WIN64") == "0":
        pytest.skip("WIN64=0: the Windows engine was not built")
    if not win64_toolchain_installed():
        pytest.skip("the Windows toolchain is not installed (`make win64-tools`): the FMUs carry linux64 only")
    assert FMUS and WIN64_FMUS == FMUS, sorted(set(p.stem for p in FMUS) - set(p.stem for p in WIN64_FMUS))
    for path in FMUS:
        assert {"linux64", "win64"} <= set(supported_platforms(str(path))), path
        md = read_model_description(path)
        with zipfile.ZipFile(path) as z:
            dll = z.read(f"binaries/win64/{md.coSimulation.modelIdentifier}.dll")
        assert dll[:2] == b"MZ", path


needs_win64 = pytest.mark.skipif(not WIN64_FMUS, reason="the FMUs carry no win64 binary (`make win64-tools`, then `make fmus`)")


@pytest.fixture(scope="session")
def wine():
    """Wine's command and environment: a prefix of our own in build/wine (made once, about
    20 s), no debug chatter."""
    exe = shutil.which("wine")
    assert exe, "wine is needed to run the win64 units (`make win64-tools` installs Debian's wine64)"
    prefix = ROOT / "build" / "wine"
    prefix.parent.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, WINEPREFIX=str(prefix), WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    env.pop("DISPLAY", None)
    subprocess.run([exe, "wineboot", "--init"], env=env, capture_output=True, timeout=300, check=True)
    return exe, env


@pytest.fixture(scope="session")
def masters(tmp_path_factory):
    """tests/c/fmu_run.c built with gcc (Linux) and with mingw-w64 (Windows)."""
    out = tmp_path_factory.mktemp("masters")
    src = ROOT / "tests" / "c" / "fmu_run.c"
    flags = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror"]
    gcc, mingw = shutil.which("gcc"), shutil.which("x86_64-w64-mingw32-gcc")
    assert gcc and mingw, "gcc and x86_64-w64-mingw32-gcc are needed (make tools, make win64-tools)"
    subprocess.run([gcc, *flags, "-o", str(out / "fmu_run"), str(src), "-ldl", "-lm"], check=True)
    subprocess.run([mingw, *flags, "-o", str(out / "fmu_run.exe"), str(src)], check=True)
    return out / "fmu_run", out / "fmu_run.exe"


class Run:
    """What fmu_run printed: rows {k: (t, values)}, statuses {call: code}, reruns, the logs of
    the run and of the misuse, the serialized state's size, the integer outputs."""

    def __init__(self, stdout):
        self.rows, self.statuses, self.reruns = {}, {}, {}
        self.logs, self.misuse_logs = [], []
        self.state_size = self.integers = self.after_misuse = None
        self.done = False
        misuse = False
        for line in stdout.splitlines():
            kind, _, rest = line.partition(" ")
            if kind == "row":
                k, t, *values = rest.split()
                self.rows[int(k)] = (bits(t), [bits(v) for v in values])
            elif kind == "status":
                call, code = rest.rsplit(" ", 1)
                self.statuses[call] = int(code)
            elif kind == "rerun":
                name, n = rest.split()
                self.reruns[name] = int(n)
            elif kind == "state_size":
                self.state_size = int(rest)
            elif kind == "integers":
                self.integers = [int(x) for x in rest.split()]
            elif kind == "after_misuse":
                self.after_misuse = [bits(v) for v in rest.split()]
            elif kind == "misuse":
                misuse = True
            elif kind == "log":
                (self.misuse_logs if misuse else self.logs).append(rest)
            elif kind == "done":
                self.done = True


class Unit:
    """One extracted FMU and the arguments of fmu_run for it."""

    def __init__(self, path, tmp, case):
        self.name, inp, stop, step = case
        self.md = read_model_description(path)
        self.dir = Path(extract(path, unzipdir=tmp / self.name))
        ident = self.md.coSimulation.modelIdentifier
        self.so = self.dir / "binaries" / "linux64" / f"{ident}.so"
        self.dll = self.dir / "binaries" / "win64" / f"{ident}.dll"
        self.resources = self.dir / "resources"
        ex = self.md.defaultExperiment
        self.stop = stop if stop is not None else float(ex.stopTime)
        self.step = step if step is not None else float(ex.stepSize)
        variables = {v.name: v for v in self.md.modelVariables}
        outs = [v for v in self.md.modelVariables if v.causality == "output"]
        self.reals = [v.name for v in outs if v.type == "Real"]
        self.units = {v.name: v.unit for v in outs if v.type == "Real"}
        self.ints = [v.name for v in outs if v.type == "Integer"]
        self.tolerance = float(variables["solver.tolerance"].start)
        self.adaptive = variables["solver.adaptive"].start in ("true", "1", True)
        self.options = []
        if self.ints:
            self.options += ["--integers", ",".join(str(variables[n].valueReference) for n in self.ints)]
        if inp:
            name, amplitude = inp
            self.options += ["--input", f"{variables[name].valueReference}={hex_bits(amplitude)}"]
            self.options += ["--nan", str(variables[name].valueReference)]
        else:
            self.options += ["--nan", str(variables["solver.tolerance"].valueReference)]
        self.vrs = ",".join(str(variables[n].valueReference) for n in self.reals)

    def args(self, library, uri, *extra):
        return [library, uri, self.md.guid, hex_bits(self.stop), hex_bits(self.step), self.vrs, *self.options, *extra]

    def linux(self, masters, *extra):
        cmd = [str(masters[0]), *self.args(str(self.so), self.resources.as_uri(), *extra)]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, f"linux64 unit: {r.stderr[-2000:]}\n{r.stdout[-2000:]}"
        return Run(r.stdout)

    def windows(self, masters, wine, *extra):
        exe, env = wine
        uri = PureWindowsPath(windows_path(self.resources)).as_uri()  # file:///Z:/..., as fmpy on Windows
        cmd = [exe, str(masters[1]), *self.args(windows_path(self.dll), uri, *extra)]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
        assert r.returncode == 0, f"win64 unit under Wine: {r.stderr[-2000:]}\n{r.stdout[-2000:]}"
        return Run(r.stdout)

    def rtol(self):
        return (ADAPTIVE_RTOL if self.adaptive else FIXED_RTOL) * self.tolerance


def differences(unit, lin, win, first=0):
    """{output: (max |win - lin| / scale, scale)} over the rows from `first`. The scale is the
    output's largest magnitude over the Linux run, but at least FLOOR times the largest of the
    outputs of its unit: an output that stays below that is zero by the physics (the rod's tip
    held on the slide line, the deflection at a pinned end) and shows only rounding noise."""
    assert sorted(lin.rows) == sorted(win.rows)
    rows = [k for k in lin.rows if k >= first]
    amplitude = {n: max(abs(lin.rows[k][1][i]) for k in rows) for i, n in enumerate(unit.reals)}
    by_unit = {}
    for n, a in amplitude.items():
        by_unit[unit.units[n]] = max(by_unit.get(unit.units[n], 0.0), a)
    out = {}
    for i, name in enumerate(unit.reals):
        scale = max(amplitude[name], FLOOR * by_unit[unit.units[name]])
        diff = max(abs(win.rows[k][1][i] - lin.rows[k][1][i]) for k in rows)
        out[name] = (diff / scale if scale > 0 else diff, scale)
    return out


def check_agreement(unit, lin, win, first=0):
    """Same times bit for bit; every output but solver.* within the tolerance; returns the
    largest relative difference."""
    for k in lin.rows:
        assert win.rows[k][0] == lin.rows[k][0], (k, win.rows[k][0], lin.rows[k][0])
    diffs = differences(unit, lin, win, first)
    physics = {n: d for n, d in diffs.items() if not n.startswith("solver.")}
    worst = max(physics, key=lambda n: physics[n][0])
    bad = {n: d for n, d in physics.items() if d[0] > unit.rtol()}
    assert not bad, f"{unit.name}: beyond {unit.rtol():.1e} relative: {bad}"
    if "solver.constraint_residual" in unit.reals:
        i = unit.reals.index("solver.constraint_residual")
        for run in (lin, win):
            assert max(abs(v[i]) for _, v in run.rows.values()) < unit.tolerance
    return worst, physics[worst][0]


@needs_win64
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_windows_unit_under_wine_agrees_with_the_linux_unit(case, fmu_dir, masters, wine, tmp_path):
    path = fmu_dir / f"{case[0]}.fmu"
    assert path in WIN64_FMUS, f"{path} carries no win64 binary"
    unit = Unit(path, tmp_path, case)
    lin = unit.linux(masters)
    win = unit.windows(masters, wine)
    for run, platform in ((lin, "linux64"), (win, "win64")):
        assert run.done, platform
        assert run.reruns == {"fmi2SetFMUstate": 0, "fmi2DeSerializeFMUstate": 0}, (platform, run.reruns)
    # the same statuses: every call of the run OK, the misuse refused with fmi2Error
    assert win.statuses == lin.statuses
    assert lin.statuses == {"fmi2SetReal(NaN)": FMI2_ERROR, "fmi2DoStep(negative)": FMI2_ERROR}
    assert win.misuse_logs == lin.misuse_logs, (win.misuse_logs, lin.misuse_logs)
    errors = [m for m in lin.misuse_logs if m.startswith(f"{FMI2_ERROR} ")]
    assert len(errors) == 2 and "NaN" in errors[0] and "-" in errors[1], errors
    assert win.after_misuse == [v for v in win.rows[max(win.rows)][1]]
    assert win.state_size == lin.state_size
    assert len(lin.rows) == round(unit.stop / unit.step) + 1
    worst, rel = check_agreement(unit, lin, win)
    if os.environ.get("WIN64_REPORT"):
        for name, (d, scale) in sorted(differences(unit, lin, win).items(), key=lambda x: -x[1][0]):
            print(f"  {name:32s} {d:.2e} of {scale:.3e}")
    steps = dict(zip(unit.ints, zip(lin.integers, win.integers))) if unit.ints else {}
    print(f"\n{unit.name}: largest |win64 - linux64| {rel:.2e} of the amplitude ({worst}); bound {unit.rtol():.1e};"
          f" solver counters (linux64, win64): {steps}")


@needs_win64
@pytest.mark.parametrize("case", CASES[1:2], ids=[CASES[1][0]])
def test_a_state_serialized_on_one_platform_restores_on_the_other(case, fmu_dir, masters, wine, tmp_path):
    """Restart from file across machines: the state the Linux unit saved at the middle point
    runs on in the Windows unit, and the other way round, each agreeing with the run that saved
    it within the tolerance."""
    unit = Unit(fmu_dir / f"{case[0]}.fmu", tmp_path, case)
    saved_lin, saved_win = tmp_path / "linux64.state", tmp_path / "win64.state"
    lin = unit.linux(masters, "--save", str(saved_lin))
    win = unit.windows(masters, wine, "--save", windows_path(saved_win))
    assert saved_lin.read_bytes()[:4] == saved_win.read_bytes()[:4] == b"FMI2"
    win_from_lin = unit.windows(masters, wine, "--restore", windows_path(saved_lin))
    lin_from_win = unit.linux(masters, "--restore", str(saved_win))
    mid = round(unit.stop / unit.step) // 2
    for saved, restored in ((lin, win_from_lin), (win, lin_from_win)):
        assert restored.done
        assert min(restored.rows) == mid
        part = Run("")
        part.rows = {k: v for k, v in saved.rows.items() if k >= mid}
        check_agreement(unit, part, restored, first=mid)
