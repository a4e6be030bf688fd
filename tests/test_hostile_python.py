"""Hostile input to the Python package (issue 45, items 1-3): the fmu_beam installed in this
venv (`make wheel`, or `maturin develop`), each case in a child interpreter bounded in time, so
that a crash (SIGSEGV) or a hang fails the test instead of ending pytest.

- Item 1: a beam's `matrix_file` given to `Scene.from_dict` or `Scene.from_toml` is read by the
  engine's one reader (`fmu-beam/src/scene/files.rs`): below `directory` (default: the working
  directory), a regular file, capped, and no refusal quotes the file, its size or where a link
  leads.
- Item 2: no Python object crashes the interpreter: a dict that holds itself, lists and dicts
  nested 10 000 deep, an object whose `tolist()` or `items()` returns itself, an enormous one:
  each raises SceneError.
- Item 3: `Scene.package()` never replaces what is not a regular file (a FIFO, a directory, a
  link to /dev/null), and replaces a regular file whole.
"""

import os
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from fmu_util import ROOT

SCENE = ROOT / "scenes" / "pendulum_3d_matrix.toml"
MATRIX = ROOT / "scenes" / "matrices" / "pendulum_3d_element.txt"
SECRET = "root:$y$j9T$SECRETSECRET:19000:0:99999:7:::"

PRELUDE = textwrap.dedent(
    """
    import os, sys, tomllib
    import fmu_beam
    from fmu_beam import Scene, SceneError
    SCENE = {scene!r}
    def matrix_dict(name):
        with open(SCENE, "rb") as f:
            d = tomllib.load(f)
        d["beam"][0]["matrix_file"] = name
        return d
    RULES = ["below the scene's directory", "must be a regular file"]
    def refused(call):
        try:
            call()
        except SceneError as e:
            print("REFUSED", e)
            refused.rule = e.rule
            return str(e)
        print("ACCEPTED")
        return None
    """
)


def child(code, cwd, timeout=60):
    """Runs `code` after PRELUDE in a fresh interpreter in `cwd`, at most `timeout` s: (exit
    status, standard output and error). A hang fails the test."""
    program = PRELUDE.format(scene=str(SCENE)) + textwrap.dedent(code)
    try:
        done = subprocess.run([sys.executable, "-"], input=program, cwd=cwd,
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        pytest.fail(f"the child did not return within {timeout} s (a hang):\n{code}")
    return done.returncode, done.stdout + done.stderr


def refused_cleanly(code, cwd, timeout=60):
    """The child ran to its end (no signal, exit 0) and printed REFUSED: its output."""
    rc, out = child(code, cwd, timeout)
    assert rc == 0, f"exit status {rc} (negative: killed by signal {-rc}):\n{out}"
    assert "REFUSED" in out, out
    return out


@pytest.fixture
def arena(tmp_path):
    """A scene directory with the matrix file, and around it files that must stay unread."""
    base = tmp_path / "scene"
    base.mkdir()
    (base / "element.txt").write_text(MATRIX.read_text())
    (tmp_path / "secret.txt").write_text(SECRET + "\n")
    (base / "to_secret.txt").symlink_to(tmp_path / "secret.txt")
    (base / "to_shadow.txt").symlink_to("/etc/shadow")
    os.mkfifo(base / "pipe.txt")
    return base


# ---- item 1: one reader for the files a scene names ----

def test_from_dict_reads_a_matrix_file_below_its_directory(arena):
    rc, out = child("""
        s = Scene.from_dict(matrix_dict("element.txt"))
        print("OK", s.name)
    """, arena)
    assert rc == 0 and "OK pendulum_3d_matrix" in out, out


@pytest.mark.parametrize("name", [
    "/etc/shadow", "/etc/passwd", "../secret.txt", "to_secret.txt", "to_shadow.txt",
    "/proc/self/environ", "/dev/zero", "pipe.txt", "/nonexistent/x", "missing.txt",
])
def test_from_dict_refuses_a_matrix_file_outside_unbounded_or_blocking(arena, name):
    out = refused_cleanly(f"""
        m = refused(lambda: Scene.from_dict(matrix_dict({name!r})))
        assert "matrix_file" in m, m
        # refused by the reader, before a byte is parsed
        assert any(rule in m for rule in RULES), m
    """, arena, timeout=30)
    assert "SECRET" not in out and "root:" not in out, out
    assert str(arena.parent) not in out, out  # no resolved path
    assert "characters" not in out and "PATH=" not in out, out


def test_refusals_do_not_tell_which_files_exist(arena):
    """A missing file outside, an existing one, and a link to either: the same words."""
    out = refused_cleanly("""
        def rule(name):
            refused(lambda: Scene.from_dict(matrix_dict(name)))
            return refused.rule
        assert rule("/etc/passwd") == rule("/etc/no-such-file") == rule("../secret.txt")
        assert rule("to_shadow.txt") == rule("missing.txt") == rule("to_secret.txt")
    """, arena)
    assert "/etc/shadow" not in out.replace("'to_shadow.txt'", ""), out


def test_from_dict_reads_below_the_directory_given(arena, tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    rc, out = child(f"""
        s = Scene.from_dict(matrix_dict("element.txt"), directory={str(arena)!r})
        print("OK", s.name)
        refused(lambda: Scene.from_dict(matrix_dict("../secret.txt"), directory={str(arena)!r}))
    """, elsewhere)
    assert rc == 0 and "OK pendulum_3d_matrix" in out and "REFUSED" in out, out
    assert "SECRET" not in out, out


def test_from_toml_reads_a_matrix_file_by_the_same_reader(arena):
    text = SCENE.read_text().replace("matrices/pendulum_3d_element.txt", "element.txt")
    rc, out = child(f"""
        text = {text!r}
        s = Scene.from_toml(text)
        print("OK", s.name)
        assert Scene.from_toml(text, directory=".") == s
        for name in ["/etc/shadow", "../secret.txt", "to_secret.txt", "/dev/zero", "pipe.txt"]:
            m = refused(lambda: Scene.from_toml(text.replace('"element.txt"', repr(name))))
            assert m and "matrix_file" in m and any(rule in m for rule in RULES), m
    """, arena, timeout=30)
    assert rc == 0 and "OK pendulum_3d_matrix" in out and "ACCEPTED" not in out, out
    assert "SECRET" not in out, out


# ---- item 2: no Python object crashes the interpreter ----

HOSTILE_OBJECTS = {
    "a dict that holds itself": ("holds itself", """
        d = matrix_dict("x"); d["world"] = d
    """),
    "a list that holds itself": ("holds itself", """
        d = matrix_dict("x"); l = [1.0]; l.append(l); d["world"] = {"gravity": l}
    """),
    "lists nested 10 000 deep": ("nested more than 64", """
        d = matrix_dict("x"); x = 0.0
        for _ in range(10_000): x = [x]
        d["world"] = {"gravity": x}
    """),
    "dicts nested 10 000 deep": ("nested more than 64", """
        d = matrix_dict("x"); x = {}
        for _ in range(10_000): x = {"a": x}
        d["world"] = x
    """),
    "dicts nested 100 000 deep at the top": ("nested more than 64", """
        d = {}
        for _ in range(100_000): d = {"a": d}
    """),
    "tolist() returns itself": ("holds itself", """
        class T:
            def tolist(self): return self
        d = matrix_dict("x"); d["world"] = {"gravity": T()}
    """),
    "items() returns itself": ("holds itself", """
        class I:
            def items(self): return self
            def __iter__(self): return iter([("a", self)])
        d = matrix_dict("x"); d["world"] = I()
    """),
    "items() yields itself": ("holds itself", """
        class J:
            def items(self): return [("gravity", self)]
        d = matrix_dict("x"); d["world"] = J()
    """),
    "tolist() nests deeper each call": ("nested more than 64", """
        class Deeper:
            def tolist(self): return [Deeper()]
        d = matrix_dict("x"); d["world"] = {"gravity": Deeper()}
    """),
    "items() that never ends": ("too large", """
        import itertools
        class Endless:
            def items(self): return ((f"k{i}", None) for i in itertools.count())
        d = matrix_dict("x"); d["world"] = Endless()
    """),
    "a list of ten million items": ("too large", """
        d = matrix_dict("x"); d["world"] = {"gravity": [0.0] * 10_000_000}
    """),
    "a string of a hundred million characters": ("too large", """
        d = matrix_dict("x"); d["name"] = "x" * 100_000_000
    """),
    "a dict of a million keys": ("too large", """
        d = matrix_dict("x"); d["world"] = {f"k{i}": 1 for i in range(1_000_000)}
    """),
    "a dict whose keys are not strings": ("not a string", """
        d = matrix_dict("x"); d["world"] = {(1, 2): 1.0}
    """),
    "a dict subclass whose items() lies": ("holds itself", """
        class Liar(dict):
            def items(self): raise RuntimeError("never called")
            def __iter__(self): raise RuntimeError("never called")
        d = Liar(matrix_dict("x")); d["world"] = d
    """),
}


@pytest.mark.parametrize("what", sorted(HOSTILE_OBJECTS))
def test_a_hostile_object_raises_scene_error(arena, what):
    said, code = HOSTILE_OBJECTS[what]
    code = textwrap.dedent(code) + "refused(lambda: Scene.from_dict(d))\n"
    out = refused_cleanly(code, arena, timeout=60)
    assert said in out, out
    assert len(out) < 5000, f"a message of {len(out)} characters"


@pytest.mark.parametrize("text", [
    "x = " + "[" * 100_000 + "]" * 100_000,
    "x = " + "{a = " * 100_000 + "1" + "}" * 100_000,
    "[" + "a." * 100_000 + "b]",
], ids=["arrays", "inline tables", "dotted keys"])
def test_deeply_nested_toml_text_raises_scene_error(arena, text):
    refused_cleanly(f"refused(lambda: Scene.from_toml({text!r}))\n", arena, timeout=60)


# ---- item 3: Scene.package() never replaces what is not a regular file ----

def test_package_refuses_what_is_not_a_regular_file(tmp_path):
    if not list((ROOT / "python" / "fmu_beam" / "engines").glob("*/*")):
        pytest.skip("this fmu_beam carries no engine (make wheel)")
    os.mkfifo(tmp_path / "pipe.fmu")
    (tmp_path / "dir.fmu").mkdir()
    (tmp_path / "null.fmu").symlink_to("/dev/null")
    (tmp_path / "regular.fmu").write_text("old")
    (tmp_path / "target.fmu").write_text("target")
    (tmp_path / "link.fmu").symlink_to(tmp_path / "target.fmu")
    rc, out = child(f"""
        s = Scene.load({str(ROOT / "scenes" / "cantilever_free_vibration.toml")!r})
        for name in ["pipe.fmu", "dir.fmu", "null.fmu", "link.fmu"]:
            try:
                s.package(name)
                print("WROTE", name)
            except fmu_beam.Error as e:
                print("REFUSED", name, e)
        p = s.package("regular.fmu")
        print("PACKAGED", p.path)
    """, tmp_path, timeout=120)
    assert rc == 0, out
    for name in ["pipe.fmu", "dir.fmu", "null.fmu", "link.fmu"]:
        assert f"REFUSED {name}" in out, out
    assert stat.S_ISFIFO((tmp_path / "pipe.fmu").lstat().st_mode)
    assert (tmp_path / "dir.fmu").is_dir()
    assert os.readlink(tmp_path / "null.fmu") == "/dev/null"
    assert (tmp_path / "link.fmu").is_symlink()
    assert (tmp_path / "target.fmu").read_text() == "target"
    assert (tmp_path / "regular.fmu").read_bytes()[:2] == b"PK"
    assert not [p for p in tmp_path.iterdir() if ".tmp" in p.name]
