"""The fuzz stage's FMI half (issue 45, item 9): seeded random FMI 2.0 call sequences and
random scene mutations, through the exported fmi2* functions of the built engine library.

Scenes are packaged by the harness with the engine given (`--engine`), some as shipped and some
mutated at random (numbers scaled by 1e±k, signs flipped, fields dropped: a refusal by the
packager is counted, not a failure). Each case is one instance of one unit driven by a seeded
sequence of calls: every function of the interface, in legal and illegal orders, with unknown
and NULL references, NaN, infinite, huge and tiny values, doStep sizes from 5e-324 to 1e300,
FMU states got, set, freed, serialized into buffers of the right and the wrong size, and
deserialized from mutated bytes.

Cases run in a worker process, one at a time, with a timeout each: a worker that dies (a crash:
a signal or an abort) or a case that overruns its timeout (a hang) fails the stage, and so does
a call that returns fmi2OK with a non-finite number. A refusal is an error status with the
unit's message; a status without a message is a failure too. Counts are printed at the end.

    python tests/fuzz/fmi_calls.py --engine target/release/libfmu_beam.so \
        --harness target/release/fmu-harness --seed 45 --seconds 120

`make fuzz` runs it (and, beside it, the other halves of the stage).
"""

import argparse
import ctypes as C
import json
import math
import os
import random
import re
import select
import struct
import subprocess
import sys
import tempfile
import time
import zipfile
from collections import Counter
from pathlib import Path
from xml.etree import ElementTree

ROOT = Path(__file__).resolve().parents[2]
# small scenes of every kind: planar and 3D, inputs, drives, loads, matrix files, closed loops
SCENES = [
    "cantilever_free_vibration",
    "flexible_pendulum",
    "hinged_blade_hub",
    "pendulum_3d",
    "pendulum_3d_double_lower",
    "pendulum_3d_matrix",
    "slider_crank_split_rod_force",
    "slider_crank_split_crank",
    "spin_up_omega2",
]
# s a call may take: the work budget ends a doStep within seconds by default, within about a
# minute at the largest budget a master may set
CALL_TIMEOUT = 150.0
CALLS_PER_CASE = (20, 120)
TRACE = bool(os.environ.get("FUZZ_TRACE"))  # each call, its time and status, to stderr

OK, WARNING, DISCARD, ERROR, FATAL, PENDING = range(6)
STATUS = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]

# ---------------------------------------------------------------------------------------------
# The worker: one engine library per unit, every export called through ctypes.

LOGGER = C.CFUNCTYPE(None, C.c_void_p, C.c_char_p, C.c_int, C.c_char_p, C.c_char_p)
ALLOC = C.CFUNCTYPE(C.c_void_p, C.c_size_t, C.c_size_t)
FREE = C.CFUNCTYPE(None, C.c_void_p)
STEP_FINISHED = C.CFUNCTYPE(None, C.c_void_p, C.c_int)


class Callbacks(C.Structure):
    _fields_ = [
        ("logger", LOGGER),
        ("allocateMemory", ALLOC),
        ("freeMemory", FREE),
        ("stepFinished", STEP_FINISHED),
        ("componentEnvironment", C.c_void_p),
    ]


LIBC = C.CDLL(None)
LIBC.calloc.restype = C.c_void_p
LIBC.calloc.argtypes = [C.c_size_t, C.c_size_t]
LIBC.free.argtypes = [C.c_void_p]

MESSAGES = []


@LOGGER
def _log(env, instance, status, category, message):
    MESSAGES.append((status, message.decode("utf-8", "replace") if message else ""))


@ALLOC
def _alloc(n, size):
    return LIBC.calloc(n, size)


@FREE
def _free(p):
    LIBC.free(p)


P = C.c_void_p
U = C.c_uint
D = C.c_double
I = C.c_int
S = C.c_size_t
PROTOTYPES = {
    "fmi2GetTypesPlatform": (C.c_char_p, []),
    "fmi2GetVersion": (C.c_char_p, []),
    "fmi2SetDebugLogging": (I, [P, I, S, C.POINTER(C.c_char_p)]),
    "fmi2Instantiate": (P, [C.c_char_p, I, C.c_char_p, C.c_char_p, C.POINTER(Callbacks), I, I]),
    "fmi2FreeInstance": (None, [P]),
    "fmi2SetupExperiment": (I, [P, I, D, D, I, D]),
    "fmi2EnterInitializationMode": (I, [P]),
    "fmi2ExitInitializationMode": (I, [P]),
    "fmi2Terminate": (I, [P]),
    "fmi2Reset": (I, [P]),
    "fmi2GetReal": (I, [P, C.POINTER(U), S, C.POINTER(D)]),
    "fmi2GetInteger": (I, [P, C.POINTER(U), S, C.POINTER(I)]),
    "fmi2GetBoolean": (I, [P, C.POINTER(U), S, C.POINTER(I)]),
    "fmi2GetString": (I, [P, C.POINTER(U), S, C.POINTER(C.c_char_p)]),
    "fmi2SetReal": (I, [P, C.POINTER(U), S, C.POINTER(D)]),
    "fmi2SetInteger": (I, [P, C.POINTER(U), S, C.POINTER(I)]),
    "fmi2SetBoolean": (I, [P, C.POINTER(U), S, C.POINTER(I)]),
    "fmi2SetString": (I, [P, C.POINTER(U), S, C.POINTER(C.c_char_p)]),
    "fmi2GetFMUstate": (I, [P, C.POINTER(P)]),
    "fmi2SetFMUstate": (I, [P, P]),
    "fmi2FreeFMUstate": (I, [P, C.POINTER(P)]),
    "fmi2SerializedFMUstateSize": (I, [P, P, C.POINTER(S)]),
    "fmi2SerializeFMUstate": (I, [P, P, C.c_char_p, S]),
    "fmi2DeSerializeFMUstate": (I, [P, C.c_char_p, S, C.POINTER(P)]),
    "fmi2GetDirectionalDerivative": (
        I,
        [P, C.POINTER(U), S, C.POINTER(U), S, C.POINTER(D), C.POINTER(D)],
    ),
    "fmi2SetRealInputDerivatives": (I, [P, C.POINTER(U), S, C.POINTER(I), C.POINTER(D)]),
    "fmi2GetRealOutputDerivatives": (I, [P, C.POINTER(U), S, C.POINTER(I), C.POINTER(D)]),
    "fmi2DoStep": (I, [P, D, D, I]),
    "fmi2CancelStep": (I, [P]),
    "fmi2GetStatus": (I, [P, I, C.POINTER(I)]),
    "fmi2GetRealStatus": (I, [P, I, C.POINTER(D)]),
    "fmi2GetIntegerStatus": (I, [P, I, C.POINTER(I)]),
    "fmi2GetBooleanStatus": (I, [P, I, C.POINTER(I)]),
    "fmi2GetStringStatus": (I, [P, I, C.POINTER(C.c_char_p)]),
}

# numbers a hostile master sends
HOSTILE = [
    math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, -5e-324, 1e-300, 1e-12, 1e-3, 0.5, 1.0,
    -1.0, 1e6, 1e15, 1e300, -1e300, 2.0**63, 1.7976931348623157e308,
]
STEPS = [5e-324, 1e-300, 1e-15, 1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 0.1, 1.0, 1e3, 1e6, 1e300,
         0.0, -1e-3, math.nan, math.inf]


class Unit:
    """An extracted FMU: its engine library with every export typed, its GUID and variables."""

    def __init__(self, directory):
        self.dir = Path(directory)
        root = ElementTree.parse(self.dir / "modelDescription.xml").getroot()
        self.guid = root.get("guid").encode()
        ident = root.find("CoSimulation").get("modelIdentifier")
        self.lib = C.CDLL(str(self.dir / "binaries" / "linux64" / f"{ident}.so"))
        for name, (restype, argtypes) in PROTOTYPES.items():
            f = getattr(self.lib, name)
            f.restype, f.argtypes = restype, argtypes
        self.vars = {}
        for v in root.iter("ScalarVariable"):
            kind = next(iter(v)).tag
            self.vars.setdefault(kind, []).append(int(v.get("valueReference")))
            if v.get("causality") == "input":
                self.vars.setdefault("input", []).append(int(v.get("valueReference")))
            if v.get("causality") == "output" and kind == "Real":
                self.vars.setdefault("output", []).append(int(v.get("valueReference")))
        self.resources = (self.dir / "resources").as_uri().encode()


class Failure(Exception):
    pass


def run_case(unit, seed, counts):
    """One instance of `unit` driven by the call sequence of `seed`; counts go into `counts`
    (function -> Counter of statuses). Raises Failure on an OK with a non-finite number or a
    refusal without a message."""
    rng = random.Random(seed)
    lib = unit.lib
    callbacks = Callbacks(_log, _alloc, _free, STEP_FINISHED(), None)
    MESSAGES.clear()
    name = rng.choice([b"fuzz", b"", b"x" * 5000])
    guid = unit.guid if rng.random() < 0.95 else rng.choice([b"", b"{not-the-guid}"])
    c = lib.fmi2Instantiate(name, 1 if rng.random() < 0.97 else rng.choice([0, 7, -1]),
                            guid, unit.resources, C.byref(callbacks), 0, rng.random() < 0.5)
    counts["fmi2Instantiate"]["OK" if c else "NULL"] += 1
    if not c:
        return 1
    t = 0.0
    states = []
    blobs = []

    last = [time.monotonic()]

    def status(fname, s):
        print("-", flush=True)  # the parent's heartbeat: a call returned
        if TRACE:
            now = time.monotonic()
            print(f"{now - last[0]:8.3f} s {fname} -> {s} {MESSAGES[-1:]}", file=sys.stderr)
            last[0] = now
        counts[fname][STATUS[s] if 0 <= s < 6 else f"bad {s}"] += 1
        if s not in range(6):
            raise Failure(f"{fname} returned status {s}")
        if s >= DISCARD and not MESSAGES:
            raise Failure(f"{fname} returned {STATUS[s]} without a message")
        MESSAGES.clear()
        return s

    def finite(fname, values):
        bad = [x for x in values if not math.isfinite(x)]
        if bad:
            raise Failure(f"{fname} returned fmi2OK with non-finite values {bad[:4]}")

    def refs(kind=None):
        pool = unit.vars.get(kind or rng.choice(["Real", "Integer", "Boolean"]), [])
        n = rng.choice([0, 1, 1, 2, 3, 8])
        out = []
        for _ in range(n):
            r = rng.random()
            out.append(rng.choice(pool) if pool and r < 0.8
                       else rng.choice([0, 1, 4095, 2**31, 2**32 - 1]) if r < 0.95
                       else rng.randrange(2**32))
        return out

    def arr(ctype, values):
        return (ctype * max(len(values), 1))(*values)

    calls = rng.randint(*CALLS_PER_CASE)
    # most cases start as a master does, so that the calls after reach the running unit
    if rng.random() < 0.7:
        status("fmi2SetupExperiment", lib.fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0))
        status("fmi2EnterInitializationMode", lib.fmi2EnterInitializationMode(c))
        status("fmi2ExitInitializationMode", lib.fmi2ExitInitializationMode(c))
    for _ in range(calls):
        op = rng.randrange(26)
        if op == 0:
            tol, start, stop = (rng.choice(HOSTILE) for _ in range(3))
            start = start if rng.random() < 0.6 else 0.0
            if status("fmi2SetupExperiment", lib.fmi2SetupExperiment(
                    c, rng.random() < 0.5, tol, start, rng.random() < 0.5, stop)) == OK:
                t = start
        elif op == 1:
            status("fmi2EnterInitializationMode", lib.fmi2EnterInitializationMode(c))
        elif op in (2, 3):
            status("fmi2ExitInitializationMode", lib.fmi2ExitInitializationMode(c))
        elif op in (4, 5, 6, 7):
            # a step that ends in the work budget costs seconds: a few of them
            h = rng.choice(STEPS) if rng.random() < 0.2 else 10 ** rng.uniform(-5, -1.5)
            at = t if rng.random() < 0.9 else rng.choice(HOSTILE)
            s = status("fmi2DoStep", lib.fmi2DoStep(c, at, h, rng.random() < 0.5))
            if s in (OK, WARNING):
                t = at + h
            if s == DISCARD:
                v = D()
                if lib.fmi2GetRealStatus(c, 2, C.byref(v)) == OK:
                    t = v.value
                MESSAGES.clear()
        elif op in (8, 9):
            vr = refs("Real" if rng.random() < 0.7 else None)
            values = arr(D, [0.0] * len(vr))
            null = rng.random() < 0.05
            s = status("fmi2GetReal", lib.fmi2GetReal(
                c, None if null else arr(U, vr), len(vr) if not null else 3, values))
            if s == OK:
                finite("fmi2GetReal", values[: len(vr)])
        elif op == 10:
            vr = refs("Integer")
            status("fmi2GetInteger", lib.fmi2GetInteger(c, arr(U, vr), len(vr), arr(I, [0] * len(vr))))
        elif op == 11:
            vr = refs("Boolean")
            status("fmi2GetBoolean", lib.fmi2GetBoolean(c, arr(U, vr), len(vr), arr(I, [0] * len(vr))))
        elif op == 12:
            vr = refs()
            status("fmi2GetString", lib.fmi2GetString(c, arr(U, vr), len(vr), arr(C.c_char_p, [None] * len(vr))))
        elif op in (13, 14):
            vr = refs("Real" if rng.random() < 0.5 else "input")
            vals = [rng.choice(HOSTILE) if rng.random() < 0.5 else rng.uniform(-10, 10) for _ in vr]
            null = rng.random() < 0.05
            status("fmi2SetReal", lib.fmi2SetReal(c, arr(U, vr), len(vr), None if null else arr(D, vals)))
        elif op == 15:
            vr = refs("Integer")
            vals = [rng.choice([0, 1, -1, 2**31 - 1, -(2**31), 20, 700]) for _ in vr]
            status("fmi2SetInteger", lib.fmi2SetInteger(c, arr(U, vr), len(vr), arr(I, vals)))
        elif op == 16:
            vr = refs("Boolean")
            vals = [rng.choice([0, 1, 2, -1]) for _ in vr]
            status("fmi2SetBoolean", lib.fmi2SetBoolean(c, arr(U, vr), len(vr), arr(I, vals)))
        elif op == 17:
            vr = refs()
            status("fmi2SetString", lib.fmi2SetString(c, arr(U, vr), len(vr), arr(C.c_char_p, [b"x"] * len(vr))))
        elif op in (18, 19):
            st = P()
            if states and rng.random() < 0.3:
                st = states[-1]  # into an existing state
            if status("fmi2GetFMUstate", lib.fmi2GetFMUstate(c, C.byref(st))) == OK:
                if st not in states:
                    states.append(st)
            if states and rng.random() < 0.6:
                size = S()
                s = status("fmi2SerializedFMUstateSize",
                           lib.fmi2SerializedFMUstateSize(c, rng.choice(states), C.byref(size)))
                if s == OK:
                    n = size.value if rng.random() < 0.9 else max(size.value - rng.randint(1, 9), 0)
                    buf = C.create_string_buffer(max(n, 1))
                    if status("fmi2SerializeFMUstate",
                              lib.fmi2SerializeFMUstate(c, rng.choice(states), buf, n)) == OK:
                        blobs.append(buf.raw[:n])
        elif op == 20 and states:
            st = rng.choice(states)
            status("fmi2SetFMUstate", lib.fmi2SetFMUstate(c, st))
            v = D()
            if lib.fmi2GetRealStatus(c, 2, C.byref(v)) == OK:
                t = v.value
            MESSAGES.clear()
        elif op == 21 and states:
            st = states.pop(rng.randrange(len(states)))
            status("fmi2FreeFMUstate", lib.fmi2FreeFMUstate(c, C.byref(st)))
        elif op == 22:
            blob = bytearray(rng.choice(blobs) if blobs else os.urandom(rng.randint(0, 64)))
            how = rng.randrange(5)
            if how == 0 and blob:
                for _ in range(rng.randint(1, 4)):
                    blob[rng.randrange(len(blob))] ^= 1 << rng.randrange(8)
            elif how == 1:
                blob = blob[: rng.randrange(len(blob) + 1)]
            elif how == 2:
                blob += os.urandom(rng.randint(1, 32))
            elif how == 3 and len(blob) > 40:
                # a hostile number over eight bytes (the checksum then refuses it)
                at = rng.randrange(13, len(blob) - 8)
                blob[at:at + 8] = struct.pack("<d", rng.choice(HOSTILE))
            st = P()
            s = status("fmi2DeSerializeFMUstate",
                       lib.fmi2DeSerializeFMUstate(c, bytes(blob), len(blob), C.byref(st)))
            if s == OK:
                states.append(st)
        elif op == 23:
            vu, vk = refs("output"), refs("input")
            dv = [rng.choice(HOSTILE) if rng.random() < 0.3 else 1.0 for _ in vk]
            out = arr(D, [0.0] * len(vu))
            s = status("fmi2GetDirectionalDerivative", lib.fmi2GetDirectionalDerivative(
                c, arr(U, vu), len(vu), arr(U, vk), len(vk), arr(D, dv), out))
            if s == OK and all(math.isfinite(x) for x in dv):
                finite("fmi2GetDirectionalDerivative", out[: len(vu)])
        elif op == 24:
            vr = refs("input")
            order = [rng.choice([1, 2, 0, 3, -1]) for _ in vr]
            vals = [rng.choice(HOSTILE) for _ in vr]
            status("fmi2SetRealInputDerivatives",
                   lib.fmi2SetRealInputDerivatives(c, arr(U, vr), len(vr), arr(I, order), arr(D, vals)))
            vr = refs("output")
            status("fmi2GetRealOutputDerivatives", lib.fmi2GetRealOutputDerivatives(
                c, arr(U, vr), len(vr), arr(I, [1] * len(vr)), arr(D, [0.0] * len(vr))))
        else:
            kind = rng.choice([0, 1, 2, 3, 4, -1, 99])
            which = rng.randrange(9)
            if which == 0:
                status("fmi2GetStatus", lib.fmi2GetStatus(c, kind, C.byref(I())))
            elif which == 1:
                v = D()
                if status("fmi2GetRealStatus", lib.fmi2GetRealStatus(c, kind, C.byref(v))) == OK:
                    finite("fmi2GetRealStatus", [v.value])
            elif which == 2:
                status("fmi2GetIntegerStatus", lib.fmi2GetIntegerStatus(c, kind, C.byref(I())))
            elif which == 3:
                status("fmi2GetBooleanStatus", lib.fmi2GetBooleanStatus(c, kind, C.byref(I())))
            elif which == 4:
                status("fmi2GetStringStatus", lib.fmi2GetStringStatus(c, kind, C.byref(C.c_char_p())))
            elif which == 5:
                status("fmi2CancelStep", lib.fmi2CancelStep(c))
            elif which == 6:
                cats = rng.choice([[], [b"logEvents"], [b"logAll", b"nope"], [None]])
                status("fmi2SetDebugLogging", lib.fmi2SetDebugLogging(
                    c, rng.random() < 0.5, len(cats), arr(C.c_char_p, cats) if cats else None))
            elif which == 7:
                status("fmi2Terminate", lib.fmi2Terminate(c))
            else:
                status("fmi2Reset", lib.fmi2Reset(c))
                t = 0.0
    for st in states:
        status("fmi2FreeFMUstate", lib.fmi2FreeFMUstate(c, C.byref(st)))
    lib.fmi2FreeInstance(c)
    if lib.fmi2GetVersion() != b"2.0" or lib.fmi2GetTypesPlatform() != b"default":
        raise Failure("fmi2GetVersion or fmi2GetTypesPlatform changed")
    return calls + 1


def worker():
    """Runs the cases the parent sends (a JSON line each), answers a JSON line each."""
    units = {}
    for line in sys.stdin:
        case = json.loads(line)
        unit = units.get(case["unit"]) or units.setdefault(case["unit"], Unit(case["unit"]))
        counts = {}

        class Auto(dict):
            def __missing__(self, key):
                self[key] = Counter()
                return self[key]

        counts = Auto()
        try:
            calls = run_case(unit, case["seed"], counts)
            answer = {"calls": calls, "counts": {k: dict(v) for k, v in counts.items()}}
        except Failure as e:
            answer = {"failure": str(e), "counts": {k: dict(v) for k, v in counts.items()}}
        print(json.dumps(answer), flush=True)


# ---------------------------------------------------------------------------------------------
# The parent: packages the units, mutates scenes, hands cases out and watches the worker.

NUMBER = re.compile(r"(?<![\w.\-+])-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?(?![\w.])")


def mutate(text, rng):
    """The scene text with a few numbers scaled by 1e±k or their signs flipped, and a few
    `key = value` lines dropped."""
    lines = text.splitlines()
    for _ in range(rng.randint(1, 4)):
        k = rng.randrange(len(lines))
        line = lines[k]
        if line.lstrip().startswith("#"):
            continue
        if "=" in line and rng.random() < 0.25 and not line.lstrip().startswith("["):
            lines[k] = ""  # a field dropped
            continue
        numbers = list(NUMBER.finditer(line))
        if not numbers:
            continue
        m = rng.choice(numbers)
        x = float(m.group())
        if rng.random() < 0.3:
            y = -x
        else:
            y = x * 10.0 ** rng.choice([-300, -30, -12, -6, -3, -1, 1, 3, 6, 12, 30, 300])
        text_y = repr(y) if "." in m.group() or "e" in m.group().lower() or not y.is_integer() else str(int(y))
        lines[k] = line[: m.start()] + text_y + line[m.end():]
    return "\n".join(lines) + "\n"


def package(harness, engine, scene, out):
    r = subprocess.run([harness, "package", str(scene), "-o", str(out), "--binary", engine],
                       capture_output=True, text=True, timeout=120)
    return r.returncode == 0, r.stderr


class Worker:
    def __init__(self):
        self.p = subprocess.Popen([sys.executable, __file__, "--worker"], stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, text=True, bufsize=1)
        self.fd, self.buffer = self.p.stdout.fileno(), b""

    def line(self, timeout):
        """The worker's next line, "" when it ended, None when none came within `timeout` s
        (read from the descriptor: select sees no line a Python buffer holds)."""
        while b"\n" not in self.buffer:
            ready, _, _ = select.select([self.fd], [], [], timeout)
            if not ready:
                return None
            chunk = os.read(self.fd, 1 << 16)
            if not chunk:
                return ""
            self.buffer += chunk
        line, self.buffer = self.buffer.split(b"\n", 1)
        return line.decode()

    def run(self, case, timeout):
        """The worker's answer, or ("crash", code) or ("hang", None): a call that does not
        return within `timeout` s is a hang."""
        self.p.stdin.write(json.dumps(case) + "\n")
        self.p.stdin.flush()
        while True:
            line = self.line(timeout)
            if line is None:
                self.p.kill()
                self.p.wait()
                return "hang", None
            if line == "":
                return "crash", self.p.wait()
            if line.strip() != "-":
                return "answer", json.loads(line)

    def close(self):
        if self.p.poll() is None:
            self.p.stdin.close()
            self.p.wait(timeout=30)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--engine", default=str(ROOT / "target/release/libfmu_beam.so"))
    ap.add_argument("--harness", default=str(ROOT / "target/release/fmu-harness"))
    ap.add_argument("--seed", type=int, default=45)
    ap.add_argument("--seconds", type=float, default=120.0)
    ap.add_argument("--mutants", type=int, default=60, help="mutated scenes to package")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        return worker()
    started = time.monotonic()
    rng = random.Random(args.seed)
    work = Path(tempfile.mkdtemp(prefix="fmu-fuzz-"))
    units, mutants = [], Counter()
    for name in SCENES:
        fmu = work / f"{name}.fmu"
        ok, err = package(args.harness, args.engine, ROOT / "scenes" / f"{name}.toml", fmu)
        if not ok:
            sys.exit(f"fuzz: the shipped scene {name} does not package: {err}")
        units.append(fmu)
    for k in range(args.mutants):
        base = rng.choice(SCENES)
        text = mutate((ROOT / "scenes" / f"{base}.toml").read_text(), rng)
        scene = work / "scenes" / f"m{k}_{base}.toml"
        scene.parent.mkdir(exist_ok=True)
        scene.write_text(text)
        # a matrix file a scene names lies beside it
        if "matrix_file" in text:
            (scene.parent / "matrices").mkdir(exist_ok=True)
            for f in (ROOT / "scenes" / "matrices").iterdir():
                (scene.parent / "matrices" / f.name).write_bytes(f.read_bytes())
        ok, err = package(args.harness, args.engine, scene, work / f"m{k}.fmu")
        if ok:
            units.append(work / f"m{k}.fmu")
            mutants["packaged"] += 1
        elif "panicked" in err or "RUST_BACKTRACE" in err:
            sys.exit(f"fuzz: the packager panicked on {scene}: {err}")
        else:
            mutants["refused"] += 1
    dirs = []
    for fmu in units:
        d = work / "x" / fmu.stem
        with zipfile.ZipFile(fmu) as z:
            z.extractall(d)
        dirs.append(str(d))
    totals, failures, cases, calls = {}, [], 0, 0
    w = Worker()
    case_rng = random.Random(args.seed + 1)
    while time.monotonic() - started < args.seconds:
        case = {"unit": case_rng.choice(dirs), "seed": case_rng.randrange(2**32)}
        kind, answer = w.run(case, CALL_TIMEOUT)
        cases += 1
        if kind != "answer":
            failures.append(f"{kind} (exit {answer}) in case {case}")
            w = Worker()
            continue
        calls += answer.get("calls", 0)
        for f, c in answer["counts"].items():
            totals.setdefault(f, Counter()).update(c)
        if "failure" in answer:
            failures.append(f"{answer['failure']} in case {case}")
    w.close()
    took = time.monotonic() - started
    print(f"fuzz (FMI calls): seed {args.seed}, {took:.0f} s, {len(units)} units "
          f"({mutants['packaged']} mutated scenes packaged, {mutants['refused']} refused by the "
          f"packager), {cases} cases, {calls} calls")
    for f in sorted(totals):
        parts = ", ".join(f"{s} {n}" for s, n in sorted(totals[f].items()))
        print(f"  {f:30} {parts}")
    refusals = sum(c.get("Error", 0) for c in totals.values())
    print(f"  refusals (fmi2Error): {refusals}; discards: "
          f"{sum(c.get('Discard', 0) for c in totals.values())}")
    if failures:
        print(f"fuzz: {len(failures)} failure(s):")
        for f in failures:
            print("  " + f)
        sys.exit(1)
    print("fuzz: no crash, no hang, no non-finite output with fmi2OK")


if __name__ == "__main__":
    main()
