"""The packager as a user runs it: the same scene gives a byte-identical FMU, a wrong scene is
refused with a message naming the file, the field and the rule, and `modes` reports the C1
frequencies of the reference table."""

import zipfile

import pytest
from fmpy.validation import validate_fmu

from fmu_util import C1, harness_modes, run_harness

# (case, edit of the C1 scene text, words the message must name: the field and the rule)
WRONG_SCENES = [
    ("misspelled_key", ("length = 2.0", "lenght = 2.0"), ["lenght", "unknown field"]),
    ("negative_length", ("length = 2.0", "length = -2"), ["beam \"beam\".length", "must be positive"]),
    ("zero_elements", ("elements = 10", "elements = 0"), ["beam \"beam\".elements", "must be at least 1"]),
    ("missing_section", ('section = { shape = "rectangle", a = 0.01, b = 0.01 }\n', ""), ["section", "missing"]),
    ("nan_length", ("length = 2.0", "length = nan"), ["beam \"beam\".length", "finite"]),
    ("bad_tolerance", ("tolerance = 1e-8", "tolerance = 2.0"), ["solver.tolerance", "below 1"]),
]

# The Windows engine as the Makefile builds it (WIN64_ENGINE there).
WIN64_ENGINE = "target/win64/x86_64-win7-windows-gnu/release/fmu_beam.dll"

# C1, CASES.md: FE eigenfrequencies (Hz) of the N = 10 consistent-mass Hermite model.
C1_FE_HZ = [2.0854751, 13.069871, 36.604123, 71.779550, 118.84259]


def test_packaging_twice_gives_byte_identical_fmus(harness, root, tmp_path):
    scene = root / "scenes" / f"{C1}.toml"
    a, b = tmp_path / "a" / f"{C1}.fmu", tmp_path / "b" / f"{C1}.fmu"
    for out in (a, b):
        r = run_harness(harness, "package", scene, "-o", out)
        assert r.returncode == 0, r.stderr
    assert a.read_bytes() == b.read_bytes()
    assert validate_fmu(str(a)) == []
    assert sorted(p.name for p in a.parent.iterdir()) == [f"{C1}.fmu"]


def test_packaged_fmu_matches_make_fmus(harness, root, c1_fmu, tmp_path):
    """`make fmus` and a user's own packaging with the same engines (the default Linux one,
    and the Windows one when `make fmus` packaged it) give the same file."""
    out = tmp_path / f"{C1}.fmu"
    engines = []
    with zipfile.ZipFile(c1_fmu) as z:
        if f"binaries/win64/{C1}.dll" in z.namelist():
            engines = ["--binary", root / "target" / "release" / "libfmu_beam.so",
                       "--binary", f"win64={root / WIN64_ENGINE}"]
    r = run_harness(harness, "package", root / "scenes" / f"{C1}.toml", "-o", out, *engines)
    assert r.returncode == 0, r.stderr
    assert out.read_bytes() == c1_fmu.read_bytes(), f"{c1_fmu} is stale: run `make fmus`"


@pytest.mark.parametrize("case, edit, words", WRONG_SCENES, ids=[c[0] for c in WRONG_SCENES])
def test_wrong_scene_is_refused_naming_file_field_and_rule(harness, root, tmp_path, case, edit, words):
    text = (root / "scenes" / f"{C1}.toml").read_text()
    assert edit[0] in text
    scene = tmp_path / f"{case}.toml"
    scene.write_text(text.replace(edit[0], edit[1], 1))
    out = tmp_path / f"{case}.fmu"
    r = run_harness(harness, "package", scene, "-o", out)
    assert r.returncode != 0
    assert r.returncode == 2, r.stderr
    assert "panicked" not in r.stderr
    assert r.stderr.startswith("error: ")
    assert str(scene) in r.stderr, r.stderr
    for w in words:
        assert w in r.stderr, r.stderr
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [scene.name]


def test_modes_of_c1_equal_the_fe_reference_to_6_digits(harness, root):
    f = harness_modes(harness, root / "scenes" / f"{C1}.toml", count=5)
    assert len(f) == 5
    for got, want in zip(f, C1_FE_HZ):
        assert got == pytest.approx(want, rel=5e-7), (f, C1_FE_HZ)


def test_modes_prints_the_requested_count_with_nine_digits(harness, root):
    r = run_harness(harness, "modes", root / "scenes" / f"{C1}.toml", "--count", 3)
    assert r.returncode == 0, r.stderr
    # what was linearized first (C1: at rest, its clamp a weld, nothing to lock), then the modes
    head, lines = r.stdout.splitlines()[:3], r.stdout.splitlines()[3:]
    assert head == ["linearized at rest about the initial placement", "joints locked: none",
                    "rigid-body modes: 0 (left out)"], r.stdout
    assert [l.split(":")[0] for l in lines] == ["mode 1", "mode 2", "mode 3"]
    for line in lines:
        number = line.split(":")[1].split()[0]
        assert len(number.replace(".", "").lstrip("0")) == 9, line
        assert line.endswith(" Hz")
