"""``Scene.simulate``: a scene run in process with its unit's own engine, as fmpy runs the
packaged FMU, its results as a pandas DataFrame indexed by time.

The master loop is fmpy's ``simulate_fmu`` for FMI 2.0 co-simulation, call for call
(fmi2SetupExperiment, the start values, the inputs at the start time in initialization mode,
fmi2ExitInitializationMode, then for each communication point: the inputs, fmi2DoStep, the
outputs), and its communication points are fmpy's (``start + (n + 1) * step``, a point put on
every input event, the last step shortened to land on the stop time), so that a run equals the
packaged unit's run through fmpy at the same settings, bit for bit (tests/test_python_simulate.py).
"""

import logging
import math
from math import isclose
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Union

from fmu_beam._native import Error, SimulationError, Unit

LOG = logging.getLogger("fmu_beam")

#: Communication steps of one run: more is refused before the run starts (the command line's
#: limit, 1e8: a day at 1 ms is 8.6e7).
MAX_COMMUNICATION_STEPS = 1e8

#: Values one run may record (rows times columns): 2e8, 1.6 GB of float64.
MAX_VALUES = 2e8

#: How a time series input reaches the unit between communication points.
INTERPOLATIONS = ("linear", "hold")


def _experiment(scene) -> Dict[str, Any]:
    return scene.to_dict().get("experiment", {})


def _positive_finite(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise Error(f"{name} must be a number, not {type(value).__name__}") from None
    if not math.isfinite(x):
        raise Error(f"{name} = {x!r} must be finite")
    return x


class _Series:
    """Inputs given as time series, linear between their samples; repeated sample times are
    events (a jump), on which communication points land."""

    def __init__(self, names: List[str], t, table):
        import numpy as np

        self.names = names
        self.t = t
        self.table = table  # inputs x samples
        events = {math.inf}
        if t.size >= 2:
            events.update(t[np.where(np.diff(t) == 0)].tolist())
        self.events = sorted(events)

    def next_event(self, time: float) -> float:
        for t in self.events:
            if t > time and not isclose(t, time):
                return t
        return math.inf

    def held(self, time: float, after_event: bool):
        """The values at `time` as fmpy's ``Input.interpolate`` gives them for continuous inputs
        (interpolated between the samples, the first and last held outside them, the value after
        an event once it is reached); fmpy holds them over the step."""
        import numpy as np

        t, table = self.t, self.table
        if t.size < 2:
            return table[:, 0]
        i0 = int(np.searchsorted(t, time))
        if i0 == 0:
            return table[:, 0]
        if i0 == len(t):
            return table[:, -1]
        if isclose(time, t[i0]) and i0 < len(t) - 1 and isclose(t[i0], t[i0 + 1]):
            if after_event:
                while i0 < len(t) - 1 and isclose(t[i0], t[i0 + 1]):
                    i0 += 1
            return table[:, i0]
        i0 -= 1
        i1 = i0 + 1
        t0, t1 = t[i0], t[i1]
        w0 = (t1 - time) / (t1 - t0)
        w1 = 1 - w0
        return w0 * table[:, i0] + w1 * table[:, i1]

    def ahead(self, time: float):
        """The values at `time` and the slopes of the segments that start there (the samples
        within rounding of `time`, an event's last one included, count as passed), for the
        unit to follow over the step; outside the samples the end values, slope 0."""
        import numpy as np

        t, table = self.t, self.table
        i1 = int(np.searchsorted(t, time, side="right"))
        while i1 < len(t) and isclose(time, t[i1]):
            i1 += 1
        if i1 == 0:
            return table[:, 0], np.zeros(table.shape[0])
        if i1 == len(t):
            return table[:, -1], np.zeros(table.shape[0])
        i0 = i1 - 1
        t0, t1 = t[i0], t[i1]
        slope = (table[:, i1] - table[:, i0]) / (t1 - t0)
        w0 = (t1 - time) / (t1 - t0)
        return w0 * table[:, i0] + (1 - w0) * table[:, i1], slope


def _series(inputs, input_names: Sequence[str]) -> _Series:
    """The time series of `inputs` (a DataFrame indexed by time or with a 'time' column, or a
    dict of arrays with a 'time' key), checked."""
    import numpy as np
    import pandas as pd

    if isinstance(inputs, pd.Series):
        inputs = inputs.to_frame()
    if isinstance(inputs, pd.DataFrame):
        frame = inputs
        if "time" in frame.columns:
            t = frame["time"].to_numpy(dtype=float)
            columns = {c: frame[c] for c in frame.columns if c != "time"}
        else:
            t = frame.index.to_numpy(dtype=float)
            columns = {c: frame[c] for c in frame.columns}
    elif isinstance(inputs, Mapping):
        if "time" not in inputs:
            raise Error("inputs as a dict of arrays need a 'time' array")
        t = np.asarray(inputs["time"], dtype=float)
        columns = {k: v for k, v in inputs.items() if k != "time"}
    else:
        raise Error(
            "inputs: a DataFrame (indexed by time), a dict of arrays with 'time', or a callable "
            f"(t, outputs) -> {{name: value}}, not {type(inputs).__name__}"
        )
    if t.ndim != 1 or t.size == 0:
        raise Error("inputs: the time must be a non-empty 1-D array")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0):
        raise Error("inputs: the times must be finite and non-decreasing")
    names = []
    rows = []
    for name, values in columns.items():
        name = str(name)
        if name not in input_names:
            raise Error(f"inputs: the unit has no input {name} (its inputs: {', '.join(input_names) or 'none'})")
        v = np.asarray(values, dtype=float)
        if v.shape != t.shape:
            raise Error(f"inputs: {name} has {v.size} values for {t.size} times")
        if not np.all(np.isfinite(v)):
            raise Error(f"inputs: {name} holds a value that is not finite")
        names.append(name)
        rows.append(v)
    if not names:
        raise Error("inputs: no input column")
    return _Series(names, t, np.vstack(rows))


def simulate(
    scene,
    stop_time: Optional[float] = None,
    step_size: Optional[float] = None,
    outputs: Optional[Sequence[str]] = None,
    start_values: Optional[Mapping[str, Any]] = None,
    inputs: Union[None, Any, Callable[[float, Dict[str, float]], Mapping[str, float]]] = None,
    interpolation: str = "linear",
    start_time: Optional[float] = None,
):
    """Runs the scene in process with its unit's engine and returns a pandas DataFrame indexed
    by time (s), one column per output; ``df.attrs["units"]`` maps each column to its unit
    (None: dimensionless), ``df.attrs["messages"]`` holds the warnings the unit logged and
    ``df.attrs["notes"]`` its information (a split step...; both also sent to the ``logging``
    logger ``fmu_beam``, as warnings and as info).

    - ``stop_time``, ``step_size`` (the communication step), ``start_time``: default the
      scene's ``[experiment]``.
    - ``outputs``: variable names to record (default: every output of the unit).
    - ``start_values``: ``{name: value}`` for any parameter the unit exposes, set before
      initialization (checked by the scene's rules, all or nothing).
    - ``inputs``: time series (a DataFrame indexed by time, or a dict of arrays with a 'time'
      key) of the unit's inputs, or a callable ``(t, outputs) -> {name: value}`` called at
      every communication point before the step from ``t`` (``outputs``: the recorded row at
      ``t`` as a dict), for a controller loop; its values are held over the step.
    - ``interpolation`` of time series: ``"linear"`` (default: the value at each communication
      point and the slope of its segment, which the unit follows over the step through
      fmi2SetRealInputDerivatives, so the result does not depend on the communication step) or
      ``"hold"`` (the value at each communication point, held: fmpy's default).

    A step the unit cannot take raises :class:`fmu_beam.SimulationError` with ``time`` (the
    last good time), ``reason``, ``ended`` and ``rows`` (the DataFrame up to ``time``).
    """
    import numpy as np
    import pandas as pd

    experiment = _experiment(scene)
    start = _positive_finite("start_time", experiment.get("start_time", 0.0) if start_time is None else start_time)
    stop = _positive_finite("stop_time", experiment.get("stop_time", 1.0) if stop_time is None else stop_time)
    step = _positive_finite("step_size", experiment.get("step_size", 1e-3) if step_size is None else step_size)
    if step <= 0:
        raise Error(f"step_size = {step!r} must be positive")
    if stop <= start:
        raise Error(f"stop_time = {stop!r} must be after start_time = {start!r}")
    if interpolation not in INTERPOLATIONS:
        raise Error(f"interpolation must be one of {', '.join(INTERPOLATIONS)}, not {interpolation!r}")
    points = (stop - start) / step
    if points > MAX_COMMUNICATION_STEPS:
        raise Error(
            f"{points:.3g} communication steps (stop_time {stop!r}, step_size {step!r}) is more than "
            f"{MAX_COMMUNICATION_STEPS:.0e}: take a larger step"
        )

    unit = Unit(scene)
    variables = {name: (ty, causality) for name, ty, causality, _, _ in unit.variables()}
    if outputs is None:
        names = list(unit.output_names())
    elif isinstance(outputs, str):
        names = [outputs]
    else:
        names = list(dict.fromkeys(str(n) for n in outputs))
    unknown = [n for n in names if n not in variables]
    if unknown:
        raise Error(f"{scene.name}: the unit has no variable {', '.join(unknown)}")
    if (points + 1) * max(len(names), 1) > MAX_VALUES:
        raise Error(
            f"{points:.3g} communication points of {len(names)} outputs is more than "
            f"{MAX_VALUES:.0e} values: record fewer outputs or take a larger step"
        )
    input_names = [n for n, (_, c) in variables.items() if c == "input"]

    series = None
    controller = None
    if callable(inputs) and not isinstance(inputs, (Mapping, pd.DataFrame, pd.Series)):
        controller = inputs
    elif inputs is not None:
        series = _series(inputs, input_names)
        if not all(variables[n][0] == "Real" for n in series.names):
            raise Error("inputs: time series of Real inputs only")
    derivatives = series is not None and interpolation == "linear"

    groups = {}
    for n in names:
        groups.setdefault(variables[n][0], []).append(n)
    refs = {ty: [vr for vr, _ in unit.references(ns)] for ty, ns in groups.items()}
    getters = {"Real": unit.get_real, "Integer": unit.get_integer, "Boolean": unit.get_boolean}
    order = [n for ty in ("Real", "Integer", "Boolean") for n in groups.get(ty, [])]
    column_of = {n: i for i, n in enumerate(order)}
    rows: List[list] = []
    messages: List[str] = []
    notes: List[str] = []

    def sample(time: float) -> list:
        row = [time]
        for ty in ("Real", "Integer", "Boolean"):
            if ty in refs:
                row.extend(getters[ty](refs[ty]))
        rows.append(row)
        return row

    def collect():
        for m in unit.messages():
            messages.append(m)
            LOG.warning("%s: %s", scene.name, m)
        for m in unit.notes():
            notes.append(m)
            LOG.info("%s: %s", scene.name, m)

    def frame():
        values = np.asarray([r[1:] for r in rows], dtype=np.float64).reshape(len(rows), len(order))
        df = pd.DataFrame(index=pd.Index([r[0] for r in rows], name="time", dtype=np.float64))
        for n in names:
            dtype = {"Real": np.float64, "Integer": np.int32, "Boolean": np.bool_}[variables[n][0]]
            df[n] = values[:, column_of[n]].astype(dtype)
        df.attrs["units"] = dict(unit.units(names))
        df.attrs["messages"] = list(messages)
        df.attrs["notes"] = list(notes)
        df.attrs["scene"] = scene.name
        return df

    input_refs = {}
    if series is not None:
        input_refs = dict(zip(series.names, (vr for vr, _ in unit.references(series.names))))

    def apply_series(time: float, after_event: bool):
        vrs = [input_refs[n] for n in series.names]
        if derivatives:
            values, slopes = series.ahead(time)
            unit.set_real(vrs, [float(v) for v in values])
            unit.set_input_derivatives(vrs, [float(d) for d in slopes])
        else:
            unit.set_real(vrs, [float(v) for v in series.held(time, after_event)])

    controlled: Dict[str, int] = {}

    def apply_controller(time: float, row: list):
        seen = dict(zip(order, row[1:]))
        wanted = controller(time, seen)
        if wanted is None:
            return
        if not isinstance(wanted, Mapping):
            raise Error(f"inputs: the callable returned {type(wanted).__name__}, not a dict {{name: value}}")
        keys = [str(k) for k in wanted.keys()]
        for k in keys:
            if k not in controlled:
                if k not in variables or variables[k][0] != "Real":
                    raise Error(f"inputs: the callable set {k}, which is not a Real variable of the unit")
                controlled[k] = unit.references([k])[0][0]
        unit.set_real([controlled[k] for k in keys], [float(v) for v in wanted.values()])

    tolerance = None  # the scene's solver.tolerance is the DefaultExperiment's: fmpy passes it unchanged
    unit.setup(start, tolerance)
    if start_values:
        by_type: Dict[str, List] = {}
        for name, value in start_values.items():
            name = str(name)
            if name not in variables:
                raise Error(f"start_values: the unit has no variable {name}")
            if variables[name][1] not in ("parameter", "input"):
                raise Error(f"start_values: {name} is an {variables[name][1]}, not a parameter or an input")
            by_type.setdefault(variables[name][0], []).append((name, value))
        setters = {"Real": (unit.set_real, float), "Integer": (unit.set_integer, int), "Boolean": (unit.set_boolean, bool)}
        for ty, pairs in by_type.items():
            setter, cast = setters[ty]
            vrs = [vr for vr, _ in unit.references([n for n, _ in pairs])]
            setter(vrs, [cast(v) for _, v in pairs])
    time = start
    if series is not None:
        apply_series(time, after_event=False)
    try:
        unit.exit_initialization()
    finally:
        collect()
    row = sample(time)
    n_steps = 0
    next_event = series.next_event if series is not None else (lambda _t: math.inf)
    while True:
        if time > stop or isclose(time, stop):
            break
        next_regular = start + (n_steps + 1) * step
        point = next_regular
        event = next_event(time)
        if point > event and not isclose(point, event):
            point = event
        if point > stop and not isclose(point, stop):
            point = stop
        h = point - time
        if series is not None:
            apply_series(time, after_event=True)
        elif controller is not None:
            apply_controller(time, row)
        try:
            unit.do_step(time, h)
        except SimulationError as e:
            collect()
            e.rows = frame()
            raise
        collect()
        time = point
        row = sample(time)
        if isclose(time, next_regular):
            n_steps += 1
    return frame()
