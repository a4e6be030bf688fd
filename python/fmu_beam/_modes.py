"""The results of :meth:`Scene.modes` and :meth:`Scene.campbell` (python/src/modes.rs computes
them): :class:`Modes` and the Campbell diagram's DataFrame. numpy and pandas are imported here
only, when one of those is called, so that ``import fmu_beam`` needs neither."""

from typing import Any, Dict, List, Optional, Tuple


def _array(data: bytes, shape: Tuple[int, ...] = (-1,)) -> Any:
    """The f64 values of ``data`` (native byte order, bit for bit) as a writable numpy array."""
    import numpy as np

    return np.frombuffer(data, dtype="=f8").reshape(shape).copy()


class Modes(list):  # type: ignore[type-arg]
    """The linearized modes of a scene: a list of their natural frequencies in Hz (what
    ``Scene.modes`` returned before, so ``for f in scene.modes(count=2)`` and ``json.dumps``
    still work), with numpy arrays beside it.

    - ``frequencies``: natural frequencies |s|/2π (Hz), ascending; without damping the undamped
      ones (gyroscopic terms kept at speed).
    - ``damped_frequencies``: |Im s|/2π = f √(1 − ζ²) (Hz).
    - ``damping_ratios``: ζ = −Re s/|s| from the beams' Rayleigh damping (0 without).
    - ``shapes``: coordinates × modes, each column scaled so that its largest entry is 1; the
      real part of the eigenvector after the phase that makes it as real as possible.
    - ``coordinates``: the name of each row of ``shapes``: ``<beam>.shape.x[i]``, ``.y[i]``,
      (``.z[i]``) for each shape point i (the unit's shape outputs: the nodes, 1 at flange a),
      then its section's rotation ``.phi[i]`` (planar) or ``.rx[i]``, ``.ry[i]``, ``.rz[i]``
      (3D, world axes); ``<body>.x`` ... for each rigid body's origin.

    What was linearized: ``speed`` (rad/s), ``hub``, ``locked`` and ``driven`` joints,
    ``rigid_body_modes`` (left out), ``non_oscillating`` (overdamped or diverging modes, left
    out), ``damped``, ``equilibrium``, ``off_equilibrium`` (the largest start acceleration where
    the placement is no equilibrium, else None), ``runs_planar`` (a 3D scene that runs with
    the planar element: its modes are still the 3D structure's), ``undamped_frequencies`` (Hz,
    the problem without damping)."""

    frequencies: Any
    damped_frequencies: Any
    damping_ratios: Any
    shapes: Any
    coordinates: List[str]
    undamped_frequencies: Any
    speed: float
    hub: Optional[str]
    locked: List[str]
    driven: List[str]
    rigid_body_modes: int
    non_oscillating: int
    damped: bool
    equilibrium: bool
    off_equilibrium: Optional[float]
    runs_planar: bool

    @classmethod
    def _from_native(cls, d: Dict[str, Any]) -> "Modes":
        n = d["count"]
        frequencies = _array(d["frequencies"])
        m = cls(float(f) for f in frequencies)
        m.frequencies = frequencies
        m.damped_frequencies = _array(d["damped_frequencies"])
        m.damping_ratios = _array(d["damping_ratios"])
        m.coordinates = list(d["coordinates"])
        m.shapes = _array(d["shapes"], (len(m.coordinates), n))
        m.undamped_frequencies = _array(d["undamped_frequencies"])
        for key in ("speed", "hub", "locked", "driven", "rigid_body_modes", "non_oscillating", "damped",
                    "equilibrium", "off_equilibrium", "runs_planar"):
            setattr(m, key, d[key])
        return m

    def shape(self, k: int) -> Dict[str, float]:
        """Mode ``k`` (from 0)'s shape as {coordinate: value}."""
        return dict(zip(self.coordinates, (float(x) for x in self.shapes[:, k])))

    def to_frame(self) -> Any:
        """The modes as a pandas DataFrame, one row each (``mode`` from 1): frequency,
        damped_frequency (Hz), damping_ratio; units in ``attrs``."""
        import pandas as pd

        df = pd.DataFrame(
            {"frequency": self.frequencies, "damped_frequency": self.damped_frequencies,
             "damping_ratio": self.damping_ratios},
            index=pd.RangeIndex(1, len(self) + 1, name="mode"))
        df.attrs["units"] = {"frequency": "Hz", "damped_frequency": "Hz", "damping_ratio": "1"}
        df.attrs["speed"] = self.speed
        return df

    def __repr__(self) -> str:
        at = f"at {self.speed:g} rad/s about '{self.hub}'" if self.speed else "at rest"
        shown = ", ".join(f"{f:.6g}" for f in self[:6]) + (", ..." if len(self) > 6 else "")
        return f"<fmu_beam.Modes {at}: [{shown}] Hz>"


def campbell_frame(d: Dict[str, Any]) -> Any:
    """The Campbell diagram computed by python/src/modes.rs as a DataFrame indexed by speed
    (rad/s), one column per mode (``mode1``, ... in Hz, NaN where a speed has fewer), then
    ``damping_ratio1``, ... where the scene has damping; units and what was linearized in
    ``attrs``."""
    import pandas as pd

    speeds = _array(d["speeds"])
    k = d["columns"]
    data = {}
    frequencies = _array(d["frequencies"], (len(speeds), k))
    for j in range(k):
        data[f"mode{j + 1}"] = frequencies[:, j]
    units = {f"mode{j + 1}": "Hz" for j in range(k)}
    if d["damping_ratios"] is not None:
        ratios = _array(d["damping_ratios"], (len(speeds), k))
        for j in range(k):
            data[f"damping_ratio{j + 1}"] = ratios[:, j]
            units[f"damping_ratio{j + 1}"] = "1"
    df = pd.DataFrame(data, index=pd.Index(speeds, name="speed"))
    df.attrs["units"] = {"speed": "rad/s", **units}
    for key in ("scene", "hub", "locked", "driven", "rigid_body_modes", "damped", "runs_planar"):
        if key in d:
            df.attrs[key] = d[key]
    return df
