"""The Python package (issue 30): the wheel that `make wheel` built into dist/, installed into a
fresh venv with no cargo or rustc on PATH, packages every shipped scene through the Python API
and through the `fmu-beam` command; fmpy's validator finds no problem in any of them; C1 from
the wheel runs bit for bit as the make-built unit (build/fmus/); a wrong scene raises
fmu_beam.SceneError naming the field; scenes round-trip through dicts and TOML; the README's
Python quickstart runs as written.

What it measured (wheel size, install time, packaging time) goes to build/wheel/measured.json.
"""

import json
import os
import re
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from fmu_util import C1, ROOT

DIST = ROOT / "dist"
SCENES = sorted((ROOT / "scenes").glob("*.toml"))
MEASURED = ROOT / "build" / "wheel" / "measured.json"
WIN64 = os.environ.get("WIN64", "auto") != "0"


def measured(**figures):
    """Adds figures to build/wheel/measured.json."""
    MEASURED.parent.mkdir(parents=True, exist_ok=True)
    known = json.loads(MEASURED.read_text()) if MEASURED.is_file() else {}
    known.update(figures)
    MEASURED.write_text(json.dumps(known, indent=2) + "\n")


@pytest.fixture(scope="module")
def wheel():
    found = sorted(DIST.glob("fmu_beam-*.whl"))
    linux = [w for w in found if "manylinux" in w.name]
    if not linux:
        pytest.fail(f"no Linux wheel in {DIST}: run `make wheel` first")
    return linux[-1]


@pytest.fixture(scope="module")
def venv(wheel, tmp_path_factory):
    """A fresh venv with the wheel installed (nothing else: it needs nothing else), and the
    environment its programs run in: PATH holds the venv's bin/ only, so neither cargo nor
    rustc can be found."""
    root = tmp_path_factory.mktemp("wheel_venv")
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(root)], check=True)
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(root / "bin" / "python"), "install",
         "--quiet", "--no-index", "--no-deps", str(wheel)],
        check=True,
    )
    measured(pip_install_s=round(time.perf_counter() - started, 2),
             wheel=wheel.name, wheel_bytes=wheel.stat().st_size)
    # then what the wheel declares it needs (numpy, pandas: Scene.modes, simulate, sweep), as a
    # user's `pip install` brings it (from pip's cache where .venv already fetched it); without
    # compiling pandas' and numpy's modules ahead (9.3 -> 3.9 s here), which the tests' imports
    # then compile as they load them
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(root / "bin" / "python"), "install",
         "--quiet", "--no-compile", str(wheel)],
        check=True,
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith(("CARGO", "RUSTUP", "PYTHON"))}
    env["PATH"] = str(root / "bin")
    site = next((root / "lib").glob("python3*/site-packages"))
    return {"root": root, "python": root / "bin" / "python", "env": env, "site": site}


def run_in(venv, code, *args):
    """Runs Python code in the fresh venv; returns its standard output."""
    done = subprocess.run([str(venv["python"]), "-c", code, *map(str, args)], env=venv["env"],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_the_wheel_is_manylinux_abi3_and_carries_the_engines(wheel):
    assert re.fullmatch(r"fmu_beam-[\w.]+-cp39-abi3-manylinux_2_(\d+)_x86_64(\.manylinux\w+)*\.whl",
                        wheel.name), wheel.name
    names = zipfile.ZipFile(wheel).namelist()
    assert "fmu_beam/engines/linux64/libfmu_beam.so" in names
    assert ("fmu_beam/engines/win64/fmu_beam.dll" in names) == WIN64
    for typed in ("fmu_beam/py.typed", "fmu_beam/_native.pyi", "fmu_beam/__init__.py"):
        assert typed in names
    metadata = next(n for n in names if n.endswith(".dist-info/METADATA"))
    text = zipfile.ZipFile(wheel).read(metadata).decode()
    assert "License-Expression: MIT OR Apache-2.0" in text


PACKAGE_ALL = """
import json, sys, time, shutil
from pathlib import Path
import fmu_beam
assert shutil.which("cargo") is None and shutil.which("rustc") is None
out = Path(sys.argv[1]); out.mkdir(parents=True, exist_ok=True)
seconds = {}
for scene in sys.argv[2:]:
    started = time.perf_counter()
    s = fmu_beam.Scene.load(scene)
    p = s.package(out / (Path(scene).stem + ".fmu"))
    seconds[s.name] = time.perf_counter() - started
    assert p.model_identifier == s.name, p
print(json.dumps({"seconds": seconds, "engines": sorted(fmu_beam.engines())}))
"""


@pytest.fixture(scope="module")
def api_fmus(venv, tmp_path_factory):
    out = tmp_path_factory.mktemp("api_fmus")
    report = json.loads(run_in(venv, PACKAGE_ALL, out, *SCENES))
    seconds = sorted(report["seconds"].values())
    measured(package_from_python_s={"median": round(seconds[len(seconds) // 2], 3),
                                    "max": round(seconds[-1], 3), "scenes": len(seconds)},
             engines=report["engines"])
    return out


@pytest.fixture(scope="module")
def cli_fmus(venv, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli_fmus")
    for scene in SCENES:
        fmu = out / f"{scene.stem}.fmu"
        done = subprocess.run([str(venv["root"] / "bin" / "fmu-beam"), "package", str(scene), "-o", str(fmu)],
                              env=venv["env"], capture_output=True, text=True, cwd=ROOT)
        assert done.returncode == 0, done.stderr
        assert "engines: linux64" in done.stdout
    return out


@pytest.mark.parametrize("scene", SCENES, ids=lambda s: s.stem)
def test_every_scene_packaged_from_python_and_the_command_validates(scene, api_fmus, cli_fmus):
    api, cli = api_fmus / f"{scene.stem}.fmu", cli_fmus / f"{scene.stem}.fmu"
    assert validate_fmu(str(api)) == []
    # the same scene and engines give the same bytes, whichever way it was packaged
    assert api.read_bytes() == cli.read_bytes()
    names = zipfile.ZipFile(api).namelist()
    assert f"binaries/linux64/{scene.stem}.so" in names or any(n.startswith("binaries/linux64/") for n in names)
    assert any(n.startswith("binaries/win64/") for n in names) == WIN64


def test_c1_from_the_wheel_runs_bit_for_bit_as_the_make_built_unit(api_fmus, c1_fmu):
    ours = api_fmus / f"{C1}.fmu"
    a = simulate_fmu(str(ours), stop_time=0.5, output=["beam.tip.deflection", "beam.tip.y"])
    b = simulate_fmu(str(c1_fmu), stop_time=0.5, output=["beam.tip.deflection", "beam.tip.y"])
    assert len(a) > 100
    for name in ("time", "beam.tip.deflection", "beam.tip.y"):
        assert np.array_equal(a[name], b[name]), name


WRONG = """
import json, fmu_beam
scene = fmu_beam.Scene.load("scenes/flexible_pendulum.toml").to_dict()
out = {}
def refused(d):
    try:
        fmu_beam.Scene.from_dict(d)
    except fmu_beam.SceneError as e:
        return {"message": str(e), "field": e.field, "rule": e.rule, "value": e.value,
                "code": e.code, "origin": e.origin, "is_error": isinstance(e, fmu_beam.Error)}
    return None
scene["beam"][0]["length"] = -2.0
out["negative"] = refused(scene)
scene["beam"][0]["length"] = 0.4
scene["beam"][0]["lenght"] = 0.4
out["typo"] = refused(scene)
del scene["beam"][0]["lenght"]
scene["joint"][0]["frames"] = ["world", object()]
out["object"] = refused(scene)
print(json.dumps(out))
"""


def test_a_wrong_scene_raises_scene_error_naming_the_field(venv, tmp_path):
    out = json.loads(run_in(venv, WRONG))
    negative = out["negative"]
    assert negative["field"] == 'beam "beam".length' and negative["rule"] == "must be positive"
    assert negative["message"] == '<dict>: field `beam "beam".length` = -2: must be positive'
    assert negative["value"] == "-2" and negative["origin"] == "<dict>" and negative["is_error"]
    assert negative["code"]
    assert out["typo"]["field"] == 'beam "beam".lenght'
    assert "unknown field `lenght`" in out["typo"]["rule"]
    assert out["object"]["field"] == 'joint "hinge".frames[1]'
    # the command: the packager's message on standard error, exit status 2
    bad = tmp_path / "bad.toml"
    bad.write_text((ROOT / "scenes" / "flexible_pendulum.toml").read_text().replace("length = 0.4", "length = -2"))
    done = subprocess.run([str(venv["root"] / "bin" / "fmu-beam"), "package", str(bad), "-o", str(tmp_path / "x.fmu")],
                          env=venv["env"], capture_output=True, text=True)
    assert done.returncode == 2
    assert 'field `beam "beam".length` = -2: must be positive' in done.stderr
    assert not (tmp_path / "x.fmu").exists()


ROUND_TRIP = """
import json, sys, fmu_beam
schema = fmu_beam.schema()
out = {"schema_title": schema["title"]}
for path in sys.argv[1:]:
    s = fmu_beam.Scene.load(path)
    d = s.to_dict()
    assert fmu_beam.Scene.from_dict(d) == s, path
    assert fmu_beam.Scene.from_toml(s.to_toml()) == s, path
    assert fmu_beam.Scene.from_dict(json.loads(json.dumps(d))) == s, path
c1 = fmu_beam.Scene.load("scenes/cantilever_free_vibration.toml")
out["modes"] = c1.modes(count=3)
out["explain"] = c1.explain()
out["variables"] = [v["name"] for v in c1.variables()]
print(json.dumps(out))
"""


def test_scenes_round_trip_and_the_api_says_what_the_command_says(venv, harness):
    out = json.loads(run_in(venv, ROUND_TRIP, *SCENES))
    assert out["schema_title"] == json.loads((ROOT / "scenes" / "scene.schema.json").read_text())["title"]
    scene = ROOT / "scenes" / f"{C1}.toml"
    explain = subprocess.run([str(harness), "explain", str(scene)], capture_output=True, text=True, check=True)
    assert out["explain"] == explain.stdout
    modes = subprocess.run([str(venv["root"] / "bin" / "fmu-beam"), "modes", str(scene), "--count", "3"],
                           env=venv["env"], capture_output=True, text=True, check=True)
    # the `mode k: f Hz` lines, after the lines that say what was linearized
    shown = [float(line.split()[2]) for line in modes.stdout.splitlines() if line.startswith("mode ")]
    assert len(shown) == 3 and "joints locked: none" in modes.stdout
    assert np.allclose(shown, out["modes"], rtol=1e-8)
    assert "beam.tip.deflection" in out["variables"]


def test_the_command_offers_the_subcommands(venv):
    done = subprocess.run([str(venv["root"] / "bin" / "fmu-beam"), "--help"], env=venv["env"],
                          capture_output=True, text=True)
    assert done.returncode == 0
    for command in ("package", "explain", "modes", "simulate", "animate", "cosim", "schema"):
        assert re.search(rf"^\s+{command}\s", done.stdout, re.M), command


def test_the_readme_quickstart_runs_as_written(venv, tmp_path):
    """The README's Python quickstart, run in a directory of its own with the wheel's package
    (and this venv's fmpy) importable, prints the line written under it."""
    readme = (ROOT / "README.md").read_text()
    (code,) = [b for b in re.findall(r"```python\n(.*?)```", readme, re.S) if "import fmu_beam" in b]
    expected = [line[2:] for line in code.splitlines() if line.startswith("# ")]
    if not WIN64:  # a wheel built with WIN64=0 carries the linux64 engine only
        expected = [line.replace("['linux64', 'win64']", "['linux64']") for line in expected]
    env = dict(venv["env"], PYTHONPATH=str(venv["site"]))
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == expected



def test_an_interrupted_command_ends_at_once_and_leaves_no_temporary_file(venv, c1_fmu, tmp_path):
    """Ctrl-C on `fmu-beam simulate` ends it as it ends fmu-harness: at once, with the signal's
    status, its half-written CSV removed (Python's own handler would wait for the call)."""
    import signal
    csv = tmp_path / "run.csv"
    run = subprocess.Popen([str(venv["root"] / "bin" / "fmu-beam"), "simulate", str(c1_fmu), "--stop", "1000",
                            "-o", str(csv)], env=venv["env"], stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    while not list(tmp_path.glob(".run.csv.tmp-*")) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert list(tmp_path.glob(".run.csv.tmp-*")), "the run never started its CSV"
    run.send_signal(signal.SIGINT)
    assert run.wait(timeout=10) in (130, -signal.SIGINT)
    assert list(tmp_path.iterdir()) == []


WIN64_WHEELS = sorted(DIST.glob("fmu_beam-*-win_amd64.whl"))
WIN64_HARNESS = ROOT / "target" / "win64" / "x86_64-win7-windows-gnu" / "release" / "fmu-harness.exe"


@pytest.mark.skipif(not (WIN64_WHEELS and WIN64_HARNESS.is_file()),
                    reason="no win64 wheel and Windows packager: `make wheel-win64` builds them")
def test_the_win64_wheel_and_its_packager_under_wine(wheel, api_fmus, tmp_path):
    """What can be checked of the win64 wheel without a Windows Python: its tags and files, that
    its extension imports only python3.dll (the stable ABI) and system DLLs, that it carries the
    Linux wheel's engines; and that the packager built with the same toolchain
    (fmu-harness.exe) runs under Wine and writes, with those engines, the very bytes the Linux
    wheel's API wrote, which fmpy validates, and simulates C1 with the win64 engine to the Linux
    master's numbers bit for bit. Importing the .pyd into a Windows CPython is not checked: none
    can be had here."""
    win = WIN64_WHEELS[-1]
    assert re.fullmatch(r"fmu_beam-[\w.]+-cp39-abi3-win_amd64\.whl", win.name), win.name
    z, linux = zipfile.ZipFile(win), zipfile.ZipFile(wheel)
    for name in ("fmu_beam/engines/linux64/libfmu_beam.so", "fmu_beam/engines/win64/fmu_beam.dll"):
        assert z.read(name) == linux.read(name), name
    pyd = z.read("fmu_beam/_native.pyd")
    assert pyd[:2] == b"MZ"
    (tmp_path / "_native.pyd").write_bytes(pyd)
    dump = subprocess.run(["x86_64-w64-mingw32-objdump", "-p", str(tmp_path / "_native.pyd")],
                          capture_output=True, text=True, check=True).stdout
    dlls = {d.lower() for d in re.findall(r"DLL Name: (\S+)", dump)}
    assert "python3.dll" in dlls and not any(re.fullmatch(r"python3\d+\.dll", d) for d in dlls), dlls
    assert dlls <= {"python3.dll", "kernel32.dll", "advapi32.dll", "ntdll.dll", "msvcrt.dll",
                    "userenv.dll", "ws2_32.dll", "bcrypt.dll"}, dlls
    assert "PyInit__native" in dump
    for name in z.namelist():
        if name.startswith("fmu_beam/engines/"):
            (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / name).write_bytes(z.read(name))
    prefix = ROOT / "build" / "wine"
    prefix.parent.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, WINEPREFIX=str(prefix), WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    env.pop("DISPLAY", None)
    scene = ROOT / "scenes" / f"{C1}.toml"
    (tmp_path / scene.name).write_text(scene.read_text())
    done = subprocess.run(
        ["wine", str(WIN64_HARNESS), "package", scene.name, "-o", "c1.fmu",
         "--binary", "linux64=fmu_beam/engines/linux64/libfmu_beam.so",
         "--binary", "win64=fmu_beam/engines/win64/fmu_beam.dll"],
        env=env, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert validate_fmu(str(tmp_path / "c1.fmu")) == []
    assert (tmp_path / "c1.fmu").read_bytes() == (api_fmus / f"{C1}.fmu").read_bytes()
    # the Windows master simulates the unit with its win64 engine: the Linux master's numbers
    ran = subprocess.run(["wine", str(WIN64_HARNESS), "simulate", "c1.fmu", "-o", "win.csv"],
                         env=env, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert ran.returncode == 0, ran.stderr
    subprocess.run([str(ROOT / "target" / "release" / "fmu-harness"), "simulate", "c1.fmu",
                    "-o", "linux.csv"], cwd=tmp_path, check=True, capture_output=True)
    assert (tmp_path / "win.csv").read_bytes() == (tmp_path / "linux.csv").read_bytes()
