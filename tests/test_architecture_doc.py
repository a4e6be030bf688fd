"""ARCHITECTURE.md is true and short (issue 33, item 5): every path and every code name it cites
exists, and it stays within MAX_LINES lines.

What is checked, and how:

* Tokens. Every `backticked` span of the document; inside ``` fenced blocks (diagrams), every
  path-like word and every name with `::` or an underscore, or starting with fmi2 (plain English
  there is left alone). A span `A::{b, c}` stands for `A::b` and `A::c`; a trailing call
  `f(args)` is read as `f`.
* Left alone (not names): spans with a space (CLI commands such as `make test` or
  `fmu-harness package …`, TOML such as `effects = "auto"`, formulas), numbers, spans with
  characters no path or Rust name has (operators, quotes, `%`, `#`, `=`), dotted FMU variable
  names without a path extension (`solver.split_steps`, `<beam>.shape.x[i]`), and names with
  a hyphen but no `/` (crate names, target triples).
* Paths. A span that starts with a word character or `.` and has a `/`, or ends in an
  extension of EXTENSIONS, is a path: an optional `:line` suffix is dropped, `<placeholder>`
  becomes `*`, and it must exist relative to the repository root (a glob must match
  something; a trailing `/` means a directory). Paths under the generated directories of
  GENERATED (build/, target/ …) and the entries of a packaged FMU (FMU_ENTRIES) are not in the
  repository and are not checked. A bare file name is a path
  like any other: `model.rs` must be at the root, so the document writes
  `fmu-beam/src/unit/engine/model.rs`.
* Rust names, looked up in the Rust sources of SOURCE_DIRS with comments stripped:
  - `A::b`: A is a type (struct, enum, trait, type alias) with `b` a function or constant of
    one of its `impl` blocks, a method of the trait, or a variant of the enum; or A is a module
    (file, directory or inline `mod`) that defines or re-exports `b`. Longer paths `x::A::b`
    check their last two segments this way and every other segment as a module or crate.
    A struct's fields count as its members (`Model::front`), as documents write them. A path
    rooted in another crate (OTHER_CRATES: `std::…`, `nalgebra::…`) is not checked.
  - a single name (`Stepper`, `resolve_effects`, `fmi2DoStep`, a field such as `lands`) must be
    defined (fn, struct, enum, trait, type, const, static, mod, macro, enum variant, `use`
    name) or occur as a word in the code (string literals count, comments do not).
  The crates are read as one: a name defined in any of them passes (fmu-harness's and
  fmu-bench's `Command` are one type here). Whether a citation says what the code does is for
  the reader: the check sees only that it exists.

Run as a script, `python3 tests/test_architecture_doc.py FILE.md`, it lists what FILE cites that
does not exist (e.g. an older ARCHITECTURE.md from `git show`).
"""

import fnmatch
import functools
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "ARCHITECTURE.md"
MAX_LINES = 300
SOURCE_DIRS = ["fmu-beam/src", "fmu-harness/src", "bench/src", "python/src"]
EXTENSIONS = (".rs", ".py", ".toml", ".md", ".xml", ".html", ".json", ".csv", ".c", ".txt", ".png", ".gif")
# Generated or local directories: built by make, not part of the repository.
GENERATED = ("build/", "target/", ".venv/", ".venv-bench/")
# What a packaged FMU holds (fmu-harness/src/package.rs writes them), not repository files.
FMU_ENTRIES = ("modelDescription.xml", "binaries/", "resources/", "documentation/", "scene.toml", "guid.txt")
# Path roots: this workspace's crates, and other crates (whose paths are not checked).
OWN_CRATES = {"crate", "self", "super", "fmu_beam", "fmu_harness", "fmu_bench"}
OTHER_CRATES = {"std", "core", "nalgebra", "faer", "serde", "toml", "clap", "schemars"}
CRATES = OWN_CRATES | OTHER_CRATES
RAW_STRING = re.compile(r'b?r(#*)"')
CHAR = re.compile(r"'(\\.[^']*|[^'\\])'")

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
NAME = re.compile(rf"^{IDENT}(?:::{IDENT})*$")


# --- the Rust sources -------------------------------------------------------------------------


def strip_comments(text):
    """Rust text without comments; string and char literals kept (as `code`), and a second copy
    with their contents blanked (as `shape`, for brace matching)."""
    code, shape = [], []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
            continue
        word_start = i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")
        raw = RAW_STRING.match(text, i) if c in "rb" and word_start else None
        if raw:
            end = text.find('"' + raw.group(1), raw.end())
            end = n if end < 0 else end + 1 + len(raw.group(1))
            code.append(text[i:end])
            shape.append('""')
            i = end
            continue
        if c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            code.append(text[i : j + 1])
            shape.append('""')
            i = j + 1
            continue
        ch = CHAR.match(text, i) if c == "'" else None
        if ch:
            code.append(ch.group(0))
            shape.append("' '")
            i = ch.end()
            continue
        code.append(c)
        shape.append(c)
        i += 1
    return "".join(code), "".join(shape)


def block_after(shape, start):
    """The text inside the braces of the block whose `{` is the first one at or after `start`."""
    i = shape.find("{", start)
    if i < 0:
        return ""
    depth = 0
    for j in range(i, len(shape)):
        if shape[j] == "{":
            depth += 1
        elif shape[j] == "}":
            depth -= 1
            if depth == 0:
                return shape[i + 1 : j]
    return shape[i + 1 :]


def top_level_items(body):
    """The comma-separated items of a block at its own depth."""
    items, depth, cur = [], 0, []
    for c in body:
        if c in "{([<":
            depth += 1
        elif c in "})]>":
            depth -= 1
        if c == "," and depth == 0:
            items.append("".join(cur))
            cur = []
        else:
            cur.append(c)
    items.append("".join(cur))
    return items


def use_names(shape):
    """The names `use` statements bring into a module (last segments, `as` aliases, groups)."""
    names = set()
    for m in re.finditer(r"\buse\s+([^;]+);", shape):
        for part in re.split(r"[{},]", m.group(1)):
            part = part.strip()
            alias = re.search(rf"\bas\s+({IDENT})$", part)
            if alias:
                names.add(alias.group(1))
            elif part:
                last = part.split("::")[-1].strip()
                if re.fullmatch(IDENT, last):
                    names.add(last)
    return names


class Sources:
    """What the Rust sources define: items, the members of each type and module, the words."""

    def __init__(self, dirs):
        self.defined = set()  # every item name (fn, type, const, variant, alias, module)
        self.types = set()
        self.members = {}  # type or trait name -> fn, const and variant names
        self.modules = {}  # module name -> names defined or re-exported in it
        self.words = set()
        for d in dirs:
            for path in sorted((ROOT / d).rglob("*.rs")):
                self.read(path, ROOT / d)

    def read(self, path, src):
        code, shape = strip_comments(path.read_text())
        self.words |= set(re.findall(IDENT, code))
        rel = path.relative_to(src).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] in ("mod", "lib", "main"):
            parts = parts[:-1]
        module = parts[-1] if parts else src.parent.name.replace("-", "_")
        names = self.modules.setdefault(module, set())
        for kind, name in re.findall(rf"\b(fn|struct|enum|trait|type|union|mod|const|static)\s+({IDENT})", shape):
            self.defined.add(name)
            names.add(name)
            if kind in ("struct", "enum", "trait", "type", "union"):
                self.types.add(name)
            if kind == "mod":
                self.modules.setdefault(name, set())
        for name in re.findall(rf"macro_rules!\s*({IDENT})", shape):
            self.defined.add(name)
        aliases = use_names(shape)
        names |= aliases
        self.defined |= aliases
        # inline modules: `mod x { ... }`
        for m in re.finditer(rf"\bmod\s+({IDENT})\s*\{{", shape):
            body = block_after(shape, m.start())
            self.modules.setdefault(m.group(1), set()).update(
                re.findall(rf"\b(?:fn|struct|enum|trait|type|const|static|mod)\s+({IDENT})", body)
            )
        # impl blocks and traits: their functions and constants
        for m in re.finditer(r"\bimpl\b", shape):
            head_end = shape.find("{", m.end())
            if head_end < 0:
                continue
            head = shape[m.end() : head_end]
            if ";" in head:
                continue
            head = re.sub(r"\bwhere\b.*", "", head, flags=re.S)
            targets = []
            for side in re.split(r"\bfor\b", head):
                side = re.sub(r"<[^<>]*(<[^<>]*>[^<>]*)*>", "", side).strip()
                last = re.findall(IDENT, side)
                if last:
                    targets.append(last[-1])
            body = block_after(shape, m.start())
            found = set(re.findall(rf"\b(?:fn|const|type)\s+({IDENT})", body))
            for t in targets:
                self.members.setdefault(t, set()).update(found)
        for m in re.finditer(rf"\btrait\s+({IDENT})", shape):
            body = block_after(shape, m.start())
            self.members.setdefault(m.group(1), set()).update(re.findall(rf"\b(?:fn|const|type)\s+({IDENT})", body))
        for m in re.finditer(rf"\bstruct\s+({IDENT})[^;{{(]*\{{", shape):
            body = block_after(shape, m.start())
            for item in top_level_items(body):
                item = re.sub(r"#\[[^\]]*\]", "", item).strip()
                f = re.match(rf"(?:pub(?:\([^)]*\))?\s+)?({IDENT})\s*:", item)
                if f:
                    self.members.setdefault(m.group(1), set()).add(f.group(1))
        for m in re.finditer(rf"\benum\s+({IDENT})", shape):
            body = block_after(shape, m.start())
            for item in top_level_items(body):
                item = re.sub(r"#\[[^\]]*\]", "", item).strip()
                v = re.match(IDENT, item)
                if v:
                    self.members.setdefault(m.group(1), set()).add(v.group(0))
                    self.defined.add(v.group(0))

    def missing_name(self, name):
        """Why `name` is not in the sources, or None when it is."""
        segs = name.split("::")
        if segs[0] in OTHER_CRATES:
            return None  # another crate's path
        if len(segs) == 1:
            (n,) = segs
            return None if n in self.defined or n in self.words else "not in the code"
        for s in segs[:-2]:
            if s not in CRATES and s not in self.modules and s not in self.types:
                return f"`{s}` is no module"
        owner, member = segs[-2], segs[-1]
        if owner in ("fmu_beam", "fmu_harness"):
            return None if member in self.modules.get(owner, set()) else f"`{owner}` has no `{member}`"
        if owner in CRATES:
            return None if member in self.defined else f"`{member}` is not defined"
        as_type = owner in self.types and member in self.members.get(owner, set())
        as_module = owner in self.modules and member in self.modules[owner]
        if as_type or as_module:
            return None
        if owner not in self.types and owner not in self.modules:
            return f"`{owner}` is no type or module"
        return f"`{owner}` has no `{member}`"


@functools.cache
def sources():
    return Sources(SOURCE_DIRS)


@functools.cache
def repository_files():
    out = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard"], cwd=ROOT, capture_output=True, text=True
    )
    if out.returncode == 0 and out.stdout:
        return [line for line in out.stdout.splitlines() if (ROOT / line).exists()]
    return [str(p.relative_to(ROOT)) for p in ROOT.rglob("*") if p.is_file() and ".git" not in p.parts]


# --- the document -----------------------------------------------------------------------------


def tokens(text):
    """(line number, token, from a fenced block) of every citation in a Markdown text."""
    out = []
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            for word in re.findall(r"[\w<>*./:-]+", line):
                word = word.strip(".:")
                if "/" in word or word.endswith(EXTENSIONS) or "::" in word or "_" in word or word.startswith("fmi2"):
                    out.append((number, word, True))
            continue
        for span in re.findall(r"`([^`]+)`", line):
            out.append((number, span, False))
    return out


def expand(token):
    """A token as the names or paths it cites: groups `A::{b, c}` expanded, calls dropped."""
    token = token.strip()
    group = re.fullmatch(rf"((?:{IDENT}::)+)\{{([^{{}}]*)\}}", token)
    if group:
        return [group.group(1) + item.strip() for item in group.group(2).split(",")]
    call = re.fullmatch(rf"({IDENT}(?:::{IDENT})*)\(.*\)", token)
    if call:
        return [call.group(1)]
    return [token]


def is_path(token):
    if not re.match(r"[\w.]", token) or re.search(r"\s", token):
        return False
    return "/" in token or re.sub(r":\d+(-\d+)?$", "", token).endswith(EXTENSIONS)


def missing_path(token):
    """Why the path `token` is not in the repository, or None when it is (or is not checked)."""
    path = re.sub(r":\d+(-\d+)?$", "", token)
    path = re.sub(r"<[^<>/]*>", "*", path)
    if path.startswith("./"):
        path = path[2:]
    if path.startswith(GENERATED) or path.startswith(FMU_ENTRIES) or path in FMU_ENTRIES:
        return None
    if path.startswith(("/", "..")) or not re.fullmatch(r"[\w.*?\[\]/-]+", path):
        return "not a repository path"
    files = repository_files()
    if any(ch in path for ch in "*?["):
        pattern = path.rstrip("/")
        ok = any(fnmatch.fnmatchcase(f, pattern) or fnmatch.fnmatchcase(f, pattern + "/*") for f in files)
        return None if ok else "matches nothing"
    target = ROOT / path
    if path.endswith("/"):
        return None if target.is_dir() else "no such directory"
    return None if target.exists() else "does not exist"


def stale(text):
    """Every citation of a Markdown text that does not exist: (line, token, why)."""
    found = []
    for number, token, fenced in tokens(text):
        for t in expand(token):
            if is_path(t):
                why = missing_path(t)
            elif NAME.fullmatch(t):
                if re.fullmatch(r"\d+", t):
                    continue
                why = sources().missing_name(t)
            else:
                continue  # not a name: spaces, operators, TOML, numbers, dotted variables
            if why:
                found.append((number, t, why))
    return found


def report(found):
    return "\n".join(f"  line {n}: `{t}`: {why}" for n, t, why in found)


# --- the tests --------------------------------------------------------------------------------


def test_every_cited_path_and_name_exists():
    found = stale(DOC.read_text())
    assert not found, f"ARCHITECTURE.md cites what does not exist:\n{report(found)}"


def test_it_is_short():
    lines = DOC.read_text().count("\n")
    assert lines <= MAX_LINES, f"ARCHITECTURE.md has {lines} lines, more than {MAX_LINES}"


def test_the_check_catches_drift():
    """The kinds of drift the rewrite removed fail the check; the true citations pass."""
    drift = [
        "`fmu-beam/src/engine.rs`",
        "`System::from_scene`",
        "`fmu-harness/src/work_precision.rs`",
        "`Engine::step_to`",
        "`scenes/*.nothing`",
        "`NoSuchType`",
        "`Stepper::{advance, step_once}`",
        "```\nScene ─► System::from_scene ─► x\n```",
    ]
    for text in drift:
        assert stale(text), f"not caught: {text}"
    true = (
        "`fmu-beam/src/unit/engine/mod.rs:1` `scenes/*.toml` `fmu-beam/src/unit/` `Engine::do_step` "
        "`Stepper` `resolve_effects` `fmi2DoStep` `Model::meet_inputs` `Equations::breakpoints` "
        "`OutputKind::Shape` `cosim::Summary` `fmu_beam::fmi2_types` `make test` `effects = \"auto\"` "
        "`solver.split_steps` `build/fmus/<name>.fmu` `binaries/linux64/<modelIdentifier>.so` "
        "`Command::{Package, Explain}` `Stepper::advance(t_end, land)`"
    )
    assert not stale(true), report(stale(true))


if __name__ == "__main__":
    for arg in sys.argv[1:] or [str(DOC)]:
        found = stale(Path(arg).read_text())
        print(f"{arg}: {len(found)} citation(s) that do not exist")
        print(report(found))
