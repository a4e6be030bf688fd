"""The README's first scene and its fmpy snippet are what they say (issue 16): the TOML shown is
the shipped scenes/flexible_pendulum.toml without its comments, and the snippet, run on the
packaged FMU, prints the line written under it."""

import contextlib
import io
import os
import re
import tomllib

from fmu_util import ROOT


def blocks(lang):
    return re.findall(rf"```{lang}\n(.*?)```", (ROOT / "README.md").read_text(), re.S)


def test_the_first_scene_is_the_shipped_one():
    (shown,) = blocks("toml")
    assert tomllib.loads(shown) == tomllib.loads((ROOT / "scenes" / "flexible_pendulum.toml").read_text())
    assert shown.splitlines()[0] == "#:schema ./scene.schema.json"


def test_the_fmpy_snippet_prints_what_the_readme_says(fmu_dir):
    # the fmpy snippet; the Python quickstart (`import fmu_beam`) runs in tests/test_wheel.py
    (code,) = [b for b in blocks("python") if "import fmu_beam" not in b]
    expected = [line[2:] for line in code.splitlines() if line.startswith("# at ")]
    assert len(expected) == 1
    out = io.StringIO()
    cwd = os.getcwd()
    try:
        os.chdir(ROOT)
        with contextlib.redirect_stdout(out):
            exec(compile(code, "README.md", "exec"), {})
    finally:
        os.chdir(cwd)
    assert out.getvalue().strip() == expected[0]
