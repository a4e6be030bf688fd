"""``fmu_beam.sweep``: a design study as one call. Variants of a scene (parameter start values,
or edits of the scene itself by a dotted path into its dict) run as independent tasks on all
local cores (processes, no set-up) or on a Dask cluster (a ``dask.distributed.Client``); the
result is a DataFrame, one row per variant with its reduced outputs, or the time series in long
form.

What a task ships: the scene's canonical text (a few kB; one text per distinct scene edit) and
the variant's start values. What it returns: the variant's outputs on the communication grid,
reduced on the worker where the run is on Dask. A worker caches the scenes it has parsed. Every
variant is checked before any run (its scene edits by the scene's own validation, its start
values by the unit's rules), so a typo fails at once, not after an hour. A variant whose run
fails gets its reason in its row; the others complete. Runs are deterministic: a variant's
numbers do not depend on where or with what it ran.
"""

import functools
import itertools
import math
import os
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Union

from fmu_beam._native import Error, Scene, SceneError, SimulationError, Unit

#: Variants of one sweep: more is refused before any run.
MAX_VARIANTS = 1_000_000

#: Reductions by name, applied to each output column (a pandas Series).
REDUCTIONS: Dict[str, Callable] = {
    "max": lambda s: s.max(),
    "min": lambda s: s.min(),
    "mean": lambda s: s.mean(),
    "std": lambda s: s.std(),
    "first": lambda s: s.iloc[0],
    "last": lambda s: s.iloc[-1],
    "absmax": lambda s: s.abs().max(),
    "final": lambda s: s.iloc[-1],
}


def _variants(variants) -> (List[Dict[str, Any]], Any):
    """The variants as a list of {name: value}, and the index of the result (the DataFrame's
    own, or 0..n-1)."""
    import pandas as pd

    if isinstance(variants, pd.DataFrame):
        rows = [{str(k): v for k, v in row.items()} for row in variants.to_dict(orient="records")]
        index = variants.index.copy()
        if index.name is None:
            index.name = "variant"
        return rows, index
    if isinstance(variants, Mapping):
        names = [str(k) for k in variants.keys()]
        lists = []
        for k, v in variants.items():
            if isinstance(v, (str, bytes)) or not hasattr(v, "__iter__"):
                raise Error(f"variants: {k} must be a list of values (a dict of lists is a full factorial)")
            lists.append(list(v))
            if not lists[-1]:
                raise Error(f"variants: {k} has no value")
        count = math.prod(len(v) for v in lists)
        if count > MAX_VARIANTS:
            raise Error(f"variants: {count} combinations is more than {MAX_VARIANTS}")
        rows = [dict(zip(names, combo)) for combo in itertools.product(*lists)]
        return rows, pd.RangeIndex(len(rows), name="variant")
    if isinstance(variants, Sequence) and not isinstance(variants, (str, bytes)):
        rows = []
        for i, v in enumerate(variants):
            if not isinstance(v, Mapping):
                raise Error(f"variants[{i}]: a dict of values expected, not {type(v).__name__}")
            rows.append({str(k): x for k, x in v.items()})
        return rows, pd.RangeIndex(len(rows), name="variant")
    raise Error(
        "variants: a dict of lists (full factorial), a DataFrame (one row each) or a list of dicts, "
        f"not {type(variants).__name__}"
    )


def _plain(value):
    """A numpy scalar or array as a plain Python value (the scene's dict holds those)."""
    if hasattr(value, "tolist"):
        return value.tolist()
    return value


def _edit(d: Dict[str, Any], path: str, value: Any, scene_name: str) -> None:
    """Sets `path` (dotted: `solver.max_step`, `beam.arm.elements` or `beam.0.elements`: a
    list's element by its name or its index; `beam.elements` where the list has one element) in
    the scene's dict `d`."""
    parts = path.split(".")
    node: Any = d
    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        where = ".".join(parts[: depth + 1])
        if isinstance(node, list):
            match = [e for e in node if isinstance(e, dict) and e.get("name") == part]
            if match:
                i = node.index(match[0])
            elif part.isdigit() and int(part) < len(node):
                i = int(part)
            elif len(node) == 1 and isinstance(node[0], dict) and part in node[0]:
                # the one element of a list: `beam.substructures` where there is one beam
                node = node[0]
                if last:
                    node[part] = value
                else:
                    node = node[part]
                continue
            else:
                names = [e.get("name") for e in node if isinstance(e, dict)]
                raise Error(
                    f"{scene_name}: no {'.'.join(parts[:depth]) or 'element'} named {part!r} "
                    f"(those there: {', '.join(map(str, names))}); '{path}' is neither a parameter of "
                    "the unit nor a path into the scene"
                )
            if last:
                node[i] = value
            else:
                node = node[i]
        elif isinstance(node, dict):
            if last:
                node[part] = value
            elif part in node:
                node = node[part]
            else:
                raise Error(
                    f"{scene_name}: the scene has no {where!r}: '{path}' is neither a parameter of the "
                    f"unit nor a path into the scene (its tables: {', '.join(sorted(d))})"
                )
        else:
            raise Error(f"{scene_name}: {'.'.join(parts[:depth])} is a value, so '{path}' goes nowhere")


class _Plan:
    """The checked variants: for each, the scene text it runs and its start values."""

    def __init__(self, scene: Scene, rows: List[Dict[str, Any]]):
        unit = Unit(scene)
        self.parameters = {name for name, _, causality, _, _ in unit.variables() if causality == "parameter"}
        self.texts: List[str] = []  # distinct scene texts
        self.tasks: List[tuple] = []  # (text index, start values)
        known: Dict[str, int] = {}
        base = None
        for i, row in enumerate(rows):
            start = {k: _plain(v) for k, v in row.items() if k in self.parameters}
            edits = {k: _plain(v) for k, v in row.items() if k not in self.parameters}
            if edits:
                if base is None:
                    base = scene.to_dict()
                d = _deep_copy(base)
                for path, value in edits.items():
                    _edit(d, path, value, scene.name)
                try:
                    variant = Scene.from_dict(d, origin=f"{scene.name} variant {i}")
                except SceneError:
                    raise
                text = variant.to_toml()
            else:
                variant = scene
                text = None
            key = text or ""
            if key not in known:
                known[key] = len(self.texts)
                self.texts.append(text if text is not None else scene.to_toml())
            if start:
                _check_start_values(variant, start, i)
            self.tasks.append((known[key], start))


def _deep_copy(d):
    if isinstance(d, dict):
        return {k: _deep_copy(v) for k, v in d.items()}
    if isinstance(d, list):
        return [_deep_copy(v) for v in d]
    return d


def _check_start_values(scene: Scene, start: Dict[str, Any], i: int) -> None:
    """The start values of variant `i`, set on a unit of its scene: refused as the FMU refuses
    them (the scene's rules), naming the variant."""
    unit = Unit(scene)
    kinds = {name: ty for name, ty, _, _, _ in unit.variables()}
    by_type: Dict[str, list] = {}
    for name, value in start.items():
        by_type.setdefault(kinds[name], []).append((name, value))
    setters = {"Real": (unit.set_real, float), "Integer": (unit.set_integer, int), "Boolean": (unit.set_boolean, bool)}
    for ty, pairs in by_type.items():
        setter, cast = setters[ty]
        vrs = [vr for vr, _ in unit.references([n for n, _ in pairs])]
        try:
            setter(vrs, [cast(v) for _, v in pairs])
        except (TypeError, ValueError) as e:
            raise Error(f"variant {i}: {e}") from None
        except Error as e:
            raise type(e)(f"variant {i}: {e}") from None


@functools.lru_cache(maxsize=64)
def _parsed(text: str) -> Scene:
    """A scene text parsed once per worker process."""
    return Scene.from_toml(text, origin="<sweep>")


def _run(text: str, start: Dict[str, Any], outputs: Optional[List[str]], settings: Dict[str, Any]):
    """One variant, in whatever process runs it: its DataFrame, or its failure (reason, the rows
    so far)."""
    try:
        df = _parsed(text).simulate(outputs=outputs, start_values=start or None, **settings)
        return {"frame": df}
    except SimulationError as e:
        return {"error": str(e.reason), "frame": getattr(e, "rows", None), "time": e.time}
    except Error as e:
        return {"error": str(e), "frame": None}


def _run_reduced(text, start, outputs, settings, reduce):
    """One variant on a Dask worker: run and reduced there (a small result to ship back)."""
    out = _run(text, start, outputs, settings)
    if "error" not in out and reduce is not None:
        try:
            out = {"values": _reduce(out["frame"], reduce)}
        except Exception as e:  # the user's reduction
            out = {"error": f"reduce failed: {type(e).__name__}: {e}", "frame": None}
    return out


def _reduce(df, reduce) -> Dict[str, Any]:
    """The variant's outputs reduced to named values."""
    import pandas as pd

    if isinstance(reduce, str):
        f = REDUCTIONS[reduce]
        return {c: _plain(f(df[c])) for c in df.columns}
    if isinstance(reduce, Mapping):
        out = {}
        for col, how in reduce.items():
            f = REDUCTIONS[how] if isinstance(how, str) else how
            out[col] = _plain(f(df[col]))
        return out
    value = reduce(df)
    if isinstance(value, pd.Series):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    return {"value": _plain(value)}


def _check_reduce(reduce, outputs):
    if reduce is None or callable(reduce):
        return
    if isinstance(reduce, str):
        if reduce not in REDUCTIONS:
            raise Error(f"reduce: {reduce!r} is none of {', '.join(REDUCTIONS)} (or pass a callable)")
        return
    if isinstance(reduce, Mapping):
        for col, how in reduce.items():
            if outputs is not None and col not in outputs:
                raise Error(f"reduce: {col} is not among the outputs ({', '.join(outputs)})")
            if isinstance(how, str) and how not in REDUCTIONS:
                raise Error(f"reduce: {how!r} for {col} is none of {', '.join(REDUCTIONS)}")
            if not isinstance(how, str) and not callable(how):
                raise Error(f"reduce: for {col}, a name of a reduction or a callable")
        return
    raise Error("reduce: None (the time series), a name ('max', 'last', ...), a dict {output: how} or a callable")


def local_cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def sweep(
    scene: Union[Scene, str, "os.PathLike[str]"],
    variants,
    outputs: Optional[Sequence[str]] = None,
    reduce=None,
    client=None,
    jobs: Optional[int] = None,
    stop_time: Optional[float] = None,
    step_size: Optional[float] = None,
    progress: Optional[bool] = None,
):
    """Runs `scene` once per variant and returns a pandas DataFrame.

    - ``variants``: a dict of lists (the full factorial, in key order), a DataFrame (one row per
      variant) or a list of dicts. A name that is a parameter of the unit (``beam.E``,
      ``hub.drive.omega``: see ``scene.variables()``) is a start value; any other name is a
      dotted path into the scene's dict (``solver.max_step``, ``beam.blade.substructures``: a
      list's element by name or index). Every variant is checked before any run.
    - ``outputs``: the outputs to record (default: every output of the unit).
    - ``reduce``: None (the time series, in long form: indexed by variant and time), a name
      applied to every output (``"max"``, ``"min"``, ``"mean"``, ``"std"``, ``"first"``,
      ``"last"``, ``"absmax"``), a dict ``{output: name or callable}``, or a callable
      ``df -> dict or value``: one row per variant.
    - ``client``: a ``dask.distributed.Client``: the variants run on its cluster, reduced on the
      workers. Without one they run on ``jobs`` local processes (default: every core; 1: in
      this process).
    - ``stop_time``, ``step_size``: as :meth:`Scene.simulate` (default: the scene's).
    - ``progress``: a progress bar (tqdm; default: on for 10 variants or more).

    The result has the variants' own columns, then the reduced outputs, and ``error``: None, or
    why the variant's run failed (its outputs then NaN). ``df.attrs["units"]`` holds the
    outputs' units.
    """
    import pandas as pd

    if not isinstance(scene, Scene):
        scene = Scene.load(scene)
    rows, index = _variants(variants)
    if not rows:
        raise Error("variants: none given")
    if outputs is not None:
        outputs = [outputs] if isinstance(outputs, str) else [str(o) for o in outputs]
        unit = Unit(scene)
        have = {name for name, *_ in unit.variables()}
        missing = [o for o in outputs if o not in have]
        if missing:
            raise Error(f"{scene.name}: the unit has no output {', '.join(missing)}")
    _check_reduce(reduce, outputs)
    if jobs is not None and (not isinstance(jobs, int) or jobs < 1):
        raise Error(f"jobs must be a positive count, not {jobs!r}")
    settings = {}
    if stop_time is not None:
        settings["stop_time"] = stop_time
    if step_size is not None:
        settings["step_size"] = step_size
    plan = _Plan(scene, rows)
    n = len(rows)
    show = (n >= 10) if progress is None else bool(progress)
    results: List[Optional[dict]] = [None] * n

    from tqdm.auto import tqdm

    bar = tqdm(total=n, desc=f"sweep {scene.name}", unit="run", disable=not show)
    try:
        if client is not None:
            _on_dask(client, plan, outputs, settings, reduce, results, bar)
        else:
            workers = min(jobs or local_cores(), n)
            _on_local(workers, plan, outputs, settings, results, bar)
    finally:
        bar.close()

    units = {}
    if outputs is not None or any(r.get("frame") is not None for r in results):
        some = next((r["frame"] for r in results if r.get("frame") is not None), None)
        if some is not None:
            units = dict(some.attrs.get("units", {}))
    given = pd.DataFrame(rows, index=index)
    if reduce is None:
        frames = []
        for i, r in enumerate(results):
            f = r.get("frame")
            if f is None:
                f = pd.DataFrame(index=pd.Index([], name="time", dtype=float))
            f = f.copy()
            for k, v in rows[i].items():
                f[k] = pd.Series([v] * len(f), index=f.index, dtype=object if isinstance(v, (list, tuple)) else None)
            f["error"] = r.get("error")
            f.index = pd.MultiIndex.from_arrays([[index[i]] * len(f), f.index], names=[index.name, "time"])
            frames.append(f)
        out = pd.concat(frames)
        names = list(rows[0].keys())
        out = out[names + [c for c in out.columns if c not in names]]
    else:
        values = []
        for r in results:
            if "values" in r:
                values.append(r["values"])
            elif r.get("error") is None and r.get("frame") is not None:
                try:
                    values.append(_reduce(r["frame"], reduce))
                except Exception as e:
                    r["error"] = f"reduce failed: {type(e).__name__}: {e}"
                    values.append({})
            else:
                values.append({})
        reduced = pd.DataFrame(values, index=index)
        out = pd.concat([given, reduced], axis=1)
        out["error"] = [r.get("error") for r in results]
    out.attrs["units"] = units
    out.attrs["scene"] = scene.name
    out.attrs["failed"] = sum(r.get("error") is not None for r in results)
    return out


def _on_local(workers: int, plan: _Plan, outputs, settings, results, bar):
    """The variants on `workers` local processes (spawned: the same on Linux, macOS and
    Windows, and safe beside threads); 1 runs them here. A process that dies (a crash of a
    variant, or one killed from outside) loses nothing: what was not finished runs again in a
    new pool, three rounds at most, after which a variant still not run is marked so."""
    if workers <= 1:
        for i, (t, start) in enumerate(plan.tasks):
            results[i] = _run(plan.texts[t], start, outputs, settings)
            bar.update(1)
        return
    import concurrent.futures as cf
    import multiprocessing

    pending = list(range(len(plan.tasks)))
    for _round in range(3):
        context = multiprocessing.get_context("spawn")
        with cf.ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
            futures = {
                pool.submit(_run, plan.texts[plan.tasks[i][0]], plan.tasks[i][1], outputs, settings): i
                for i in pending
            }
            for f in cf.as_completed(futures):
                try:
                    results[futures[f]] = f.result()
                    bar.update(1)
                except cf.process.BrokenProcessPool:
                    pass  # a process died: what it and the others had not finished runs again
        pending = [i for i in pending if results[i] is None]
        if not pending:
            return
    for i in pending:
        results[i] = {"error": "the processes running this variant died three times", "frame": None}
        bar.update(1)


def _on_dask(client, plan: _Plan, outputs, settings, reduce, results, bar):
    """The variants on a Dask cluster: one task each (Dask reschedules the tasks of a worker
    that is lost), reduced on the worker."""
    from distributed import as_completed

    futures = []
    for i, (t, start) in enumerate(plan.tasks):
        futures.append(
            client.submit(
                _run_reduced, plan.texts[t], start, outputs, settings, reduce,
                key=f"fmu_beam-sweep-{os.getpid()}-{id(plan)}-{i}", pure=False,
            )
        )
    position = {f.key: i for i, f in enumerate(futures)}
    for future in as_completed(futures):
        i = position[future.key]
        try:
            results[i] = future.result()
        except Exception as e:  # the cluster gave up on the task (e.g. it killed workers)
            results[i] = {"error": f"the cluster could not run it: {type(e).__name__}: {e}", "frame": None}
        bar.update(1)
