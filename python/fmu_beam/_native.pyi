"""Type stubs of the extension module fmu_beam._native (python/src/lib.rs); use it through
``fmu_beam``, which re-exports these."""

import os
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

__version__: str

from fmu_beam._modes import Modes

StrPath = Union[str, "os.PathLike[str]"]

class Error(Exception):
    """An error of fmu_beam: an engine library or a file that cannot be read or written, a
    scene whose unit cannot be built, an FMU that cannot be run."""

class SceneError(Error):
    """A scene refused by the packager's validation; the message is the packager's."""

    origin: str
    """The scene file, or '<dict>' / '<string>' (the ``origin`` given)."""
    field: Optional[str]
    """The field's path, such as 'beam "arm".length'; None when the text could not be read."""
    value: Optional[str]
    """The value refused, as written."""
    rule: Optional[str]
    """What the value breaks ('must be positive'), or the parser's message."""
    code: Optional[str]
    """The rule's code in the scene reference, or None."""

class SimulationError(Error):
    """A run that the unit could not continue: a step it refused (fmi2Discard) or a failure."""

    time: float
    """The last good time (s): the state stays there."""
    reason: str
    """The unit's message."""
    ended: bool
    """True where no smaller step can pass (the model left its range)."""
    discard: bool
    """True for a step the unit discarded (a smaller one may pass unless ``ended``)."""
    rows: Any
    """From :meth:`Scene.simulate`: a pandas DataFrame of every communication point up to
    ``time``."""

class Packaged:
    """What :meth:`Scene.package` wrote."""

    @property
    def path(self) -> str:
        """The FMU written."""
    @property
    def model_identifier(self) -> str:
        """Its modelIdentifier: the scene's name."""
    @property
    def guid(self) -> str:
        """Its GUID: a digest of its model description, scene and engines."""
    @property
    def variables(self) -> int:
        """How many variables it has."""
    @property
    def platforms(self) -> List[str]:
        """The platforms it carries an engine for, e.g. ['linux64', 'win64']."""

class Scene:
    """A validated scene: loaded from a file, read from TOML text, or built from a dict."""

    @staticmethod
    def load(path: StrPath) -> "Scene":
        """Reads and validates a scene file (TOML) as ``fmu-beam package`` does; a beam's
        ``matrix_file`` is read relative to the file. Raises :class:`SceneError`."""
    @staticmethod
    def from_toml(
        text: str, origin: str = "<string>", directory: Optional[StrPath] = None
    ) -> "Scene":
        """Parses and validates scene text (TOML); ``origin`` prefixes the messages. A beam's
        ``matrix_file`` is read below ``directory`` (default: the working directory), as
        ``from_dict`` reads it."""
    @staticmethod
    def from_dict(
        d: Mapping[str, Any], origin: str = "<dict>", directory: Optional[StrPath] = None
    ) -> "Scene":
        """Builds a scene from nested dicts and lists shaped like the TOML file (the scene
        reference applies key for key; a key set to None takes its default) and validates it as
        the packager does. A beam's ``matrix_file`` is read below ``directory`` (default: the
        working directory) by the engine's one reader: a regular file there, links followed but
        not out of it, capped. Any object is refused rather than crash: nested more than 64
        deep, holding itself, or larger than a scene file may be. Raises :class:`SceneError`
        naming the field."""
    @property
    def name(self) -> str:
        """The scene's name: the FMU's modelIdentifier."""
    @property
    def description(self) -> str:
        """The scene's description."""
    @property
    def dimensions(self) -> int:
        """2 (planar) or 3."""
    @property
    def origin(self) -> str:
        """Where the scene came from: its file, '<dict>' or '<string>'."""
    def to_toml(self) -> str:
        """The canonical TOML text: what the FMU carries as resources/scene.toml."""
    def to_dict(self) -> Dict[str, Any]:
        """The scene as nested dicts and lists, every default written out;
        ``Scene.from_dict(s.to_dict()) == s``."""
    def explain(self) -> str:
        """The accuracy the scene was tuned for (its ``[accuracy]``, if any), then the effects
        the unit simulates, why, and their estimated share of the cost."""
    # --- modes (python/src/modes.rs, python/fmu_beam/_modes.py) ---
    def modes(
        self,
        count: Optional[int] = None,
        speed: Optional[float] = None,
        lock: Union[None, bool, str, Sequence[str]] = None,
        equilibrium: bool = False,
        hub: Optional[str] = None,
    ) -> "Modes":
        """The linearized modes, at most ``count`` (all when None): a list of their natural
        frequencies in Hz (rigid-body and non-oscillating modes left out) with numpy arrays of
        damping ratios and shapes on named coordinates. At rest, or about the steady state
        spinning at ``speed`` rad/s about ``hub`` (default: the revolute joint to world with a
        motion drive); ``lock``: a joint's name, a list, or True for every joint;
        ``equilibrium``: at rest about the static equilibrium under gravity and the loads. A 3D
        scene's modes are the 3D structure's (spatial element), out-of-plane ones included."""
    def campbell(
        self,
        speeds: Sequence[float],
        count: Optional[int] = None,
        lock: Union[None, bool, str, Sequence[str]] = None,
        hub: Optional[str] = None,
        jobs: Optional[int] = None,
    ) -> Any:
        """The Campbell diagram: a pandas DataFrame indexed by ``speed`` (rad/s), one column per
        mode (``mode1`` ... in Hz: the natural frequencies of :meth:`modes` at each speed), then
        ``damping_ratio1`` ... where a beam has damping; units in ``df.attrs["units"]``. The
        speeds run on ``jobs`` threads (default: every core), with the serial run's numbers."""
    # --- end of modes ---
    def variables(self) -> List[Dict[str, Any]]:
        """The unit's variables in value-reference order: name, value_reference, causality,
        variability, type, unit, start, description."""
    def package(
        self,
        path: StrPath,
        platforms: Optional[Sequence[str]] = None,
        binaries: Optional[Mapping[str, StrPath]] = None,
        fmi_version: int = 2,
    ) -> Packaged:
        """Writes the scene's FMU to ``path`` with this package's engines of ``platforms``
        ('linux64', 'win64'; default: all it carries), or with the engine libraries of
        ``binaries`` ({'linux64': path, ...}, like ``--binary``), as an FMI 2.0 unit or, with
        ``fmi_version=3``, an FMI 3.0 one (docs/fmi-versions.md). ``path`` must be a new name
        or a regular file, replaced whole; a FIFO, device, directory or symbolic link there is
        refused (:class:`Error`) and left as it was."""
    def simulate(
        self,
        stop_time: Optional[float] = None,
        step_size: Optional[float] = None,
        outputs: Optional[Sequence[str]] = None,
        start_values: Optional[Mapping[str, Any]] = None,
        inputs: Union[None, Any, Callable[[float, Dict[str, float]], Mapping[str, float]]] = None,
        interpolation: str = "linear",
        start_time: Optional[float] = None,
    ) -> Any:
        """Runs the scene in process with its unit's engine (as fmpy runs the packaged FMU, bit
        for bit) and returns a pandas DataFrame indexed by time, one column per output (default:
        every output; units in ``df.attrs["units"]``). ``start_values``: parameters;
        ``inputs``: time series (a DataFrame indexed by time, or a dict of arrays with 'time')
        followed linearly (``interpolation="linear"``, through the input derivatives) or held
        (``"hold"``), or a callable ``(t, outputs) -> {input: value}`` called at every
        communication point. A step the unit cannot take raises :class:`SimulationError`."""
    def accuracy(
        self,
        output: Union[str, Sequence[str]],
        target: float,
        stop: Optional[float] = None,
        comm: Optional[float] = None,
        step: Optional[float] = None,
        newton: Optional[float] = None,
        levels: int = 5,
        mesh_levels: int = 3,
        recentre: bool = True,
        max_runs: int = 60,
        reference: Optional[Any] = None,
        column: Optional[Union[str, Sequence[str]]] = None,
        jobs: Optional[int] = None,
        max_work: Optional[float] = None,
        max_seconds: Optional[float] = None,
    ) -> "AccuracyStudy":
        """The accuracy study of ``fmu-beam accuracy`` (docs/accuracy.md): the cheapest fixed
        step, Newton tolerance and mesh whose error in ``output`` (a name or a list: the largest
        over the grid of |y - y*| / max |y*|) meets ``target``, ranked and budgeted by counted
        work (the same choice on any machine and under any load), run on ``jobs`` cores
        (default: all) without the GIL; Ctrl-C stops it (KeyboardInterrupt). ``reference``: a
        CSV path (time first; ``column`` names its column per output) or a pandas DataFrame
        (``column``, default the outputs' names) or Series indexed by time, holding the study's
        grid times: each run's true error is reported beside its estimate. ``max_work``: the
        counted budget (default 600); ``max_seconds``: a wall-clock safety stop (default 3600),
        whose firing makes the study INCOMPLETE."""
    def __eq__(self, other: object) -> bool: ...
    def __reduce__(self) -> Any: ...

class Unit:
    """One instance of a scene's unit in process, driven with the calls of an FMI 2.0 master
    (what :meth:`Scene.simulate` drives; for loops of your own). Variables by value reference
    (:meth:`references`)."""

    def __init__(self, scene: Scene) -> None: ...
    def variables(self) -> List[Tuple[str, str, str, str, Optional[str]]]:
        """(name, type, causality, variability, unit) of every variable, by value reference."""
    def references(self, names: Sequence[str]) -> List[Tuple[int, str]]:
        """(value reference, type) of each name."""
    def output_names(self) -> List[str]:
        """The outputs' names."""
    def setup(self, start_time: float, tolerance: Optional[float] = None) -> None:
        """fmi2SetupExperiment."""
    def set_real(self, vrs: Sequence[int], values: Sequence[float]) -> None:
        """fmi2SetReal, all or nothing."""
    def set_integer(self, vrs: Sequence[int], values: Sequence[int]) -> None:
        """fmi2SetInteger, all or nothing."""
    def set_boolean(self, vrs: Sequence[int], values: Sequence[bool]) -> None:
        """fmi2SetBoolean, all or nothing."""
    def set_input_derivatives(self, vrs: Sequence[int], values: Sequence[float]) -> None:
        """fmi2SetRealInputDerivatives of order 1."""
    def exit_initialization(self) -> None:
        """fmi2ExitInitializationMode (builds the model)."""
    def do_step(self, t: float, h: float) -> None:
        """fmi2DoStep; raises :class:`SimulationError` for a step the unit cannot take."""
    def get_real(self, vrs: Sequence[int]) -> List[float]:
        """fmi2GetReal."""
    def get_integer(self, vrs: Sequence[int]) -> List[int]:
        """fmi2GetInteger."""
    def get_boolean(self, vrs: Sequence[int]) -> List[bool]:
        """fmi2GetBoolean."""
    @property
    def time(self) -> float:
        """The last accepted communication point (s)."""
    def messages(self) -> List[str]:
        """The warnings logged since the last call."""
    def notes(self) -> List[str]:
        """The information logged since the last call (a split step, an input's inertia)."""
    def units(self, names: Sequence[str]) -> Dict[str, Optional[str]]:
        """The unit of each name (None: dimensionless)."""

class AccuracyStudy:
    """A finished accuracy study (:meth:`Scene.accuracy`)."""

    choice: Optional[Dict[str, Any]]
    """The chosen setting: step (s), newton (tolerance), mesh (text), work (counted), cpu_s;
    None where no setting of the ladders meets the target."""
    scene: Optional[Scene]
    """The scene at the chosen setting, or None."""
    estimate: Optional[float]
    """The chosen setting's predicted error (the study's norm), or None."""
    time_share: Optional[float]
    mesh_share: Optional[float]
    newton_share: Optional[float]
    """Its error's parts: the step's, the mesh's, Newton's (the difference at tolerance / 100)."""
    limited_by: Optional[str]
    """Which share limits the error."""
    margin: float
    """The safety factor the prediction is held to: 1.25 where every order is observed, else 3."""
    target: float
    outputs: List[str]
    notes: List[str]
    """Remarks: runs the budget left out, a relaxed setting that missed, the re-centring."""
    incomplete: Optional[str]
    """Why the study stopped before its end (its wall-clock safety stop), else None."""
    work: float
    cpu_seconds: float
    wall_seconds: float
    jobs: int
    runs: Any
    """A pandas DataFrame, one row per run: role, step, newton, mesh, stiffening_switched,
    estimated_error, error_<output>, true_error (with a reference), work, cpu_s, steps,
    newton_iterations, jacobians, status."""
    def markdown(self) -> str:
        """The report of ``fmu-beam accuracy``."""
    def csv(self) -> str:
        """The runs as the command's accuracy.csv."""

def schema_text() -> str:
    """The JSON Schema of scene files, as text."""

def reference_text() -> str:
    """The scene reference, as Markdown."""

def engines() -> Dict[str, str]:
    """The engine libraries this package carries: {platform: path}."""

def cli(argv: List[str], as_command: bool = False) -> int:
    """Runs the ``fmu-beam`` command with ``argv`` (the program's name first); returns the exit
    status. ``as_command``: an interrupt ends the process, its temporary files removed."""
