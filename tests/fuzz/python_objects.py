"""The fuzz stage's Python half (issue 45, item 9): hostile Python objects thrown at the
package's entry points, seeded and bounded in time.

Each case takes a shipped scene as a dict (or its TOML text) and puts hostile objects in it at
random places: containers that hold themselves, lists and dicts nested up to 100 000 deep,
objects whose `tolist()` or `items()` return themselves, raise, never end or nest deeper at
every call, subclasses of dict, list, str, float and int whose methods (`__iter__`, `items`,
`__getitem__`, `__len__`, `__str__`, `__repr__`, `__float__`, `__index__`, `__hash__`) raise or
lie, huge ints, NaN and infinities, bytes, sets, generators, strings of ten million characters
or with lone surrogates, numpy arrays and scalars, keys that are no strings. Then one entry
point: `Scene.from_dict` (most cases, with hostile `origin` and `directory` too),
`Scene.from_toml` (mutated text, or no text at all), `Scene.load` (devices, FIFOs, folders,
paths that are no paths), and on scenes that were accepted `Scene.package` (to FIFOs, folders,
links to /dev/null), `Scene.modes`, `Scene.simulate` (where the package has it) and the
`fmu-beam` command in process.

Cases run in a worker process, one at a time: a worker that dies by a signal (a crash, an
abort) or a case that overruns its timeout (a hang) fails the stage, and so does an internal
error of fmu_beam (a panic it caught: "please report it"). A refusal (SceneError, Error,
TypeError, ...) is counted, not a failure. Case i of seed s is reproduced alone with
`--seed s --case i`. Counts are printed at the end.

    .venv/bin/python tests/fuzz/python_objects.py --seed 45 --seconds 60

`make fuzz-python` runs it with the fmu_beam installed in .venv (`make wheel`).
"""

import argparse
import json
import os
import select
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCENES = [
    "cantilever_free_vibration",
    "flexible_pendulum",
    "pendulum_3d",
    "pendulum_3d_matrix",
    "slider_crank_split_rod_force",
    "spin_up_omega2",
    "hinged_blade_arm",
]
CASE_TIMEOUT = 60.0  # s: the slowest legitimate case (a package, a short simulation) takes ~2 s
BATCH = 400  # cases per worker process

# ---------------------------------------------------------------------------------------------
# The worker: builds and runs cases; prints CASE i before and RESULT i outcome after each.

WORKER = r'''
import io, itertools, json, math, os, random, resource, sys, tomllib
from pathlib import Path

ROOT = Path(sys.argv[1]); SEED = sys.argv[2]; START = int(sys.argv[3]); COUNT = int(sys.argv[4])
ARENA = Path(sys.argv[5]); SCENES = json.loads(sys.argv[6])
# an allocation the package does not bound shows as an abort (a failure), not a swapped machine
try:
    resource.setrlimit(resource.RLIMIT_AS, (12 << 30, 12 << 30))
except (ValueError, OSError):
    pass
sys.setrecursionlimit(200_000)  # the fuzzer's own builders nest deep; the package must not

import fmu_beam
from fmu_beam import Scene, SceneError
try:
    import numpy as np
except ImportError:
    np = None

TEXTS = {n: (ROOT / "scenes" / f"{n}.toml").read_text() for n in SCENES}


class Boom(Exception):
    pass


def boom(*_a, **_k):
    raise Boom("hostile method")


# -- hostile classes --------------------------------------------------------------------------
class ToListSelf:
    def tolist(self): return self

class ToListRaises:
    def tolist(self): raise Boom("tolist")

class ToListDeeper:
    def tolist(self): return [ToListDeeper()]

class ToListHuge:
    def tolist(self): return [0.0] * 5_000_000

class ItemsSelf:
    def items(self): return self
    def __iter__(self): return iter([("a", self)])

class ItemsRaises:
    def items(self): raise Boom("items")

class ItemsEndless:
    def items(self): return ((f"k{i}", None) for i in itertools.count())

class ItemsBadPairs:
    def items(self): return [("a",), ("a", 1, 2), 7, None]

class ItemsYieldsSelf:
    def items(self): return [("gravity", self)]

class GetattrRaises:
    def __getattr__(self, name): raise Boom(name)

class ReprBomb:
    def __repr__(self): return "x" * 10_000_000
    __str__ = __repr__

class ReprRaises:
    __repr__ = boom
    __str__ = boom

class HostileStr(str):
    __str__ = boom
    __repr__ = boom
    __len__ = boom
    __iter__ = boom
    def __hash__(self): return 7
    def __eq__(self, o): raise Boom("eq")

class HostileFloat(float):
    __float__ = boom
    __repr__ = boom
    __str__ = boom
    __index__ = boom

class HostileInt(int):
    __index__ = boom
    __int__ = boom
    __float__ = boom
    __repr__ = boom

class HostileDict(dict):
    items = boom
    keys = boom
    values = boom
    __iter__ = boom
    __getitem__ = boom
    __len__ = boom
    __contains__ = boom

class HostileList(list):
    __iter__ = boom
    __getitem__ = boom
    __len__ = boom

class FspathSelf:
    def __fspath__(self): return self

class FspathRaises:
    __fspath__ = boom


def nested_list(n):
    x = 0.0
    for _ in range(n):
        x = [x]
    return x


def nested_dict(n):
    x = {}
    for _ in range(n):
        x = {"a": x}
    return x


def hostile(rng, base):
    """One hostile object (`base`: the scene dict, for self-reference)."""
    kinds = [
        lambda: base,
        lambda: (lambda l: (l.append(l), l)[1])([1.0]),
        lambda: (lambda d: (d.__setitem__("x", d), d)[1])({}),
        lambda: nested_list(rng.choice([10, 63, 64, 65, 300, 10_000, 100_000])),
        lambda: nested_dict(rng.choice([10, 63, 64, 65, 300, 10_000, 100_000])),
        ToListSelf, ToListRaises, ToListDeeper, ToListHuge,
        ItemsSelf, ItemsRaises, ItemsEndless, ItemsBadPairs, ItemsYieldsSelf,
        GetattrRaises, ReprBomb, ReprRaises,
        lambda: HostileStr("beam"),
        lambda: HostileFloat(rng.choice([1.0, float("nan"), 1e300])),
        lambda: HostileInt(rng.choice([0, 1, 2**62])),
        lambda: HostileDict(name="x", length=1.0),
        lambda: HostileList([1.0, 2.0, 3.0]),
        lambda: 10 ** rng.choice([19, 400, 4000]),
        lambda: -(10 ** 30),
        lambda: rng.choice([float("nan"), float("inf"), -float("inf"), -0.0, 5e-324, 1.8e308]),
        lambda: b"\x00\xff bytes",
        lambda: bytearray(b"ba"),
        lambda: {1.0, 2.0},
        lambda: frozenset(["a"]),
        lambda: (x for x in [1.0, 2.0, 3.0]),
        lambda: range(10**18),
        lambda: 1 + 2j,
        lambda: None,
        lambda: object(),
        lambda: Ellipsis,
        lambda: type,
        lambda: (lambda: 1),
        lambda: sys,
        lambda: "x" * rng.choice([65, 100_000, 10_000_000]),
        lambda: "\ud800 lone surrogate",
        lambda: "name\x00with nul",
        lambda: {1: 2},
        lambda: {None: 1.0},
        lambda: {("a",): 1.0},
        lambda: {HostileStr("k"): 1.0},
        lambda: [None, None],
        lambda: (1.0, 2.0, 3.0),
        lambda: [hostile(rng, base) for _ in range(3)],
        lambda: {"a": hostile(rng, base)},
    ]
    if np is not None:
        kinds += [
            lambda: np.array([1.0, 2.0, 3.0]),
            lambda: np.zeros((3, 3)),
            lambda: np.array([], dtype=float),
            lambda: np.float64("nan"),
            lambda: np.int64(2**62),
            lambda: np.array([object(), None], dtype=object),
            lambda: np.array(["a", "b"]),
            lambda: np.zeros(5_000_000),
        ]
    return rng.choice(kinds)()


def places(d, path=()):
    """Every (container, key) of the dict tree `d`."""
    out = []
    if isinstance(d, dict):
        for k, v in d.items():
            out.append((d, k))
            out.extend(places(v))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            out.append((d, i))
            out.extend(places(v))
    return out


def mutated_dict(rng, name):
    d = tomllib.loads(TEXTS[name])
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        spots = places(d)
        how = rng.random()
        if how < 0.6 and spots:
            c, k = rng.choice(spots)
            c[k] = hostile(rng, d)
        elif how < 0.8:
            d[rng.choice(["world", "beam", "joint", "name", "solver", "zzz", "experiment"])] = hostile(rng, d)
        elif how < 0.9 and spots:
            c, k = rng.choice(spots)  # plain value mutations the validator judges
            c[k] = rng.choice([-1, 0, 1e300, -1e-300, "", [], {}, True])
        else:
            d = rng.choice([HostileDict(d), hostile(rng, d), [d], (d,)])
    return d


def mutated_text(rng, name):
    text = TEXTS[name]
    r = rng.random()
    if r < 0.15:
        return hostile(rng, {})
    b = bytearray(text.encode())
    for _ in range(rng.randint(1, 8)):
        i = rng.randrange(len(b))
        op = rng.random()
        if op < 0.4:
            b[i] = rng.randrange(256)
        elif op < 0.7:
            del b[i]
        else:
            b[i:i] = rng.choice([b"[", b"{", b"\"", b"=", b"\n[[beam]]\n", b"\x00", b"[" * 1000])
    s = b.decode("utf-8", "replace")
    if r > 0.9:
        s = "x = " + "[" * rng.choice([100, 10_000, 100_000]) + "]" * 3
    return s


def arena_files():
    fifo = ARENA / "pipe"
    if not fifo.exists():
        os.mkfifo(fifo)
    null = ARENA / "null.fmu"
    if not null.is_symlink():
        null.symlink_to("/dev/null")
    (ARENA / "folder").mkdir(exist_ok=True)
    return fifo, null


def read_path(rng):
    """A hostile path to read from (devices are fine to name here: they are only read)."""
    fifo, null = arena_files()
    return rng.choice([
        "/dev/zero", "/dev/null", str(fifo), str(ARENA / "folder"), str(null), "/proc/self/environ",
        "", ".", "/", "x" * 5000, "a\x00b", b"/dev/zero", FspathSelf(), FspathRaises(), 7,
        None, ReprRaises(), HostileStr("h.toml"), str(ARENA / "missing.toml"),
    ])


def write_path(rng):
    """A hostile path to write to: never a real device (a bug would replace it: the arena's
    link to /dev/null is as far as it goes)."""
    fifo, null = arena_files()
    return rng.choice([
        str(fifo), str(ARENA / "folder"), str(null), str(ARENA / "new.fmu"), str(ARENA),
        str(ARENA / "folder" / "deeper" / "x.fmu"), str(ARENA / "x" / ""), "", 7, None,
        FspathSelf(), FspathRaises(), HostileStr(str(ARENA / "h.fmu")), b"bytes.fmu",
    ])


def attempt(rng):
    """One case's entry point: (its name, a call that makes a scene), built here (the
    fuzzer's own objects) and called by the loop."""
    name = rng.choice(SCENES)
    entry = rng.random()
    if entry < 0.70:
        d = mutated_dict(rng, name)
        kwargs = {}
        if rng.random() < 0.2:
            kwargs["origin"] = rng.choice(["<dict>", "x" * 100_000, HostileStr("o"), None, 3])
        if rng.random() < 0.2:
            kwargs["directory"] = read_path(rng)
        return "from_dict", lambda: Scene.from_dict(d, **kwargs)
    if entry < 0.85:
        kwargs = {}
        if rng.random() < 0.2:
            kwargs["directory"] = read_path(rng)
        text = mutated_text(rng, name)
        return "from_toml", lambda: Scene.from_toml(text, **kwargs)
    if entry < 0.90:
        path = read_path(rng)
        return "load", lambda: Scene.load(path)
    directory = str(ROOT / "scenes")  # where a shipped scene's matrix file is
    return "from_toml as shipped", lambda: Scene.from_toml(TEXTS[name], directory=directory)


def use(rng, scene):
    """A further call on an accepted scene: (its name, the call)."""
    r = rng.random()
    if r < 0.04:
        target = write_path(rng)
        kwargs = {}
        if rng.random() < 0.3:
            kwargs["platforms"] = rng.choice([["linux64"], ["nope"], [None], "linux64", hostile(rng, {})])
        elif rng.random() < 0.3:
            kwargs["binaries"] = rng.choice([{"linux64": "/dev/zero"}, {"linux64": str(ARENA / "pipe")}, {1: 2}, hostile(rng, {})])
        return "package", lambda: scene.package(target, **kwargs)
    if r < 0.06:
        count = rng.choice([None, 0, 3, -1, 2**70, HostileInt(3), "3", float("nan")])
        return "modes", lambda: scene.modes(count=count)
    if r < 0.08 and hasattr(scene, "simulate"):
        kwargs = {"stop_time": rng.choice([0.01, 0.02, float("nan"), -1.0, 1e300, HostileFloat(0.01)])}
        if rng.random() < 0.5:
            kwargs["start_values"] = rng.choice([{"x": 1.0}, hostile(rng, {}), {HostileStr("k"): 1}, {"solver.tolerance": float("nan")}])
        if rng.random() < 0.3:
            kwargs["outputs"] = rng.choice([["nope"], hostile(rng, {}), [HostileStr("time")]])
        return "simulate", lambda: scene.simulate(**kwargs)
    if r < 0.10:
        args = rng.choice([
            ["explain", "/dev/zero"], ["explain", str(ARENA / "pipe")], ["animate", str(ARENA / "pipe"), "-o", "x.html"],
            ["simulate", str(ARENA / "pipe")], ["package", "/proc/self/environ", "-o", str(ARENA / "x.fmu")],
            ["schema", "-o", str(ARENA / "null.fmu")], ["modes", "/dev/zero"], ["bogus"],
        ])
        return "main " + args[0], lambda: fmu_beam.main(args)
    return "round trip", lambda: (scene.to_dict(), scene.to_toml(), repr(scene))


def outcome(e):
    text = ""
    try:
        text = str(e)
    except Exception:
        pass
    if "internal error of fmu_beam" in text:
        return "INTERNAL " + text[:300]
    if isinstance(e, SceneError):
        return "SceneError"
    if isinstance(e, fmu_beam.Error):
        return "Error"
    return type(e).__name__


def called(call):
    """What a call did: "accepted" or its exception's kind; the value it returned."""
    try:
        return "accepted", call()
    except RecursionError:
        raise
    except Exception as e:
        return outcome(e), None


for i in range(START, START + COUNT):
    print(f"CASE {i}", flush=True)
    rng = random.Random(f"{SEED}-{i}")
    try:
        entry, call = attempt(rng)
    except Exception as e:  # the fuzzer's own objects refused to be built
        what = f"(fuzzer) {type(e).__name__}"
    else:
        try:
            result, scene = called(call)
            what = f"{entry}: {result}"
            if scene is not None:
                name, then = use(rng, scene)
                what += f" | {name}: {called(then)[0]}"
        except RecursionError:
            what = "(fuzzer) RecursionError"  # comparing or building its own deep objects
    print(f"RESULT {i} {json.dumps(what)}", flush=True)
'''


def run_batch(python, seed, start, count, arena, deadline):
    """Runs cases start..start+count in a worker; returns (results, failure or None). The
    worker's standard output is read from its descriptor as it comes (no buffering hides a
    line), its standard error goes to a file (a full pipe would stall it)."""
    cmd = [python, "-c", WORKER, str(ROOT), str(seed), str(start), str(count), str(arena),
           json.dumps(SCENES)]
    err_path = Path(arena) / ".worker-stderr"
    with open(err_path, "w") as err_file:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=err_file, cwd=arena)
    fd = proc.stdout.fileno()
    results = []
    current = None
    started = time.monotonic()
    pending = b""

    def stop(failure=None):
        proc.kill()
        proc.wait()
        return results, failure

    while True:
        ready, _, _ = select.select([fd], [], [], 0.5)
        if ready:
            chunk = os.read(fd, 65536)
            if not chunk:
                break
            pending += chunk
            *lines, pending = pending.split(b"\n")
            for raw in lines:
                line = raw.decode("utf-8", "replace")
                if line.startswith("CASE "):
                    current = int(line.split()[1])
                    started = time.monotonic()
                elif line.startswith("RESULT "):
                    _, i, what = line.split(" ", 2)
                    results.append((int(i), json.loads(what)))
                    current = None
        if current is None and time.monotonic() > deadline:
            return stop()
        if current is not None and time.monotonic() - started > CASE_TIMEOUT:
            return stop(f"case {current} did not return within {CASE_TIMEOUT:.0f} s (a hang)")
    proc.wait()
    err = err_path.read_text(errors="replace")
    if proc.returncode < 0:
        return results, (f"case {current}: the worker died by signal {-proc.returncode} "
                         f"(a crash)\n{err[-3000:]}")
    if proc.returncode != 0:
        return results, f"case {current}: the worker failed (exit {proc.returncode})\n{err[-3000:]}"
    return results, None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", default="45")
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--jobs", type=int, default=1,
                        help="workers side by side, each on batches of its own (the cases of a "
                             "seed are the same for any number)")
    parser.add_argument("--case", type=int, help="run this case alone, and say what it did")
    parser.add_argument("--python", default=sys.executable, help="the interpreter with fmu_beam")
    a = parser.parse_args()
    check = subprocess.run([a.python, "-c", "import fmu_beam"], capture_output=True, text=True)
    if check.returncode != 0:
        sys.exit(f"fuzz-python: cannot import fmu_beam with {a.python} (`make wheel` installs "
                 f"it into .venv):\n{check.stderr[-2000:]}")
    counts = Counter()
    example = {}
    failures = []
    internal = []
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="fuzz-python-") as arena:
        if a.case is not None:
            results, failure = run_batch(a.python, a.seed, a.case, 1, arena, float("inf"))
            print(results, failure or "")
            sys.exit(1 if failure or any("INTERNAL" in w for _, w in results) else 0)
        deadline = started + a.seconds
        lock = threading.Lock()
        # batches to run: (first case, count); a batch that failed part way leaves its rest here
        rests = []
        claimed = [0]

        def claim():
            with lock:
                if len(failures) >= 3:
                    return None
                if rests:
                    return rests.pop()
                claimed[0] += BATCH
                return claimed[0] - BATCH, BATCH

        def work(own_arena):
            os.makedirs(own_arena, exist_ok=True)
            while time.monotonic() < deadline and (batch := claim()) is not None:
                start, count = batch
                results, failure = run_batch(a.python, a.seed, start, count, own_arena, deadline)
                with lock:
                    for i, what in results:
                        if "INTERNAL" in what:
                            internal.append((i, what))
                        kind = "internal error" if "INTERNAL" in what else what
                        counts[kind] += 1
                        example.setdefault(kind, i)
                    if failure:
                        failures.append(failure)
                        # go on after the failed case
                        after = (results[-1][0] + 1 if results else start) + 1
                        if after < start + count:
                            rests.append((after, start + count - after))

        # each worker in an arena of its own (the cases write to fixed names in theirs)
        threads = [threading.Thread(target=work, args=(os.path.join(arena, f"job{k}"),))
                   for k in range(max(a.jobs, 1))]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    took = time.monotonic() - started
    total = sum(counts.values())
    print(f"fuzz-python: seed {a.seed}, {total} cases in {took:.0f} s on {max(a.jobs, 1)} "
          f"worker(s) ({total / max(took, 1e-9):.0f} per s)")
    for what, n in counts.most_common():
        print(f"  {n:6d}  {what}  (e.g. case {example[what]})")
    for i, what in sorted(internal):
        print(f"FAILED: case {i}: {what}")
    for f in failures:
        print(f"FAILED: {f}")
    if failures or internal:
        print(f"fuzz-python: reproduce one case with --seed {a.seed} --case N")
        sys.exit(1)


if __name__ == "__main__":
    main()
