"""fmu_beam: flexible multibody scenes as FMI 2.0 co-simulation units (FMUs).

A scene (beams, rigid bodies, joints, drives, loads; planar or 3D) is loaded from its TOML file
or built from a dict shaped like that file, validated as the packager does, and packaged as a
standard ``.fmu`` that any FMI 2.0 co-simulation master runs (fmpy, libcosim, OMSimulator,
Simulink, Dymola). The package carries the engines the FMU embeds: ``linux64`` and, where it was
built with them, ``win64`` (see :func:`engines`).

>>> import fmu_beam
>>> scene = fmu_beam.Scene.load("scenes/flexible_pendulum.toml")
>>> scene.package("flexible_pendulum.fmu").platforms
['linux64', 'win64']

The same as a command: ``fmu-beam package scenes/flexible_pendulum.toml -o pendulum.fmu``
(``fmu-beam --help`` lists the others: explain, modes, schema, reference, simulate, cosim,
animate).
"""

import json
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional

from fmu_beam._native import Error, Packaged, Scene, SceneError, SimulationError, Unit, __version__
from fmu_beam._native import AccuracyStudy
from fmu_beam import _native
from fmu_beam._sweep import sweep
from fmu_beam._modes import Modes

__all__ = [
    "Error",
    "Packaged",
    "Scene",
    "SceneError",
    "SimulationError",
    "Unit",
    "__version__",
    "engines",
    "main",
    "reference",
    "schema",
    "sweep",
]
__all__ += ["Modes", "AccuracyStudy"]


def schema() -> Dict[str, Any]:
    """The JSON Schema of scene files (what ``scenes/scene.schema.json`` holds): every table and
    key with its type, unit and rules. A dict for :meth:`Scene.from_dict` can be checked against
    it with ``jsonschema`` too."""
    return json.loads(_native.schema_text())


def reference() -> str:
    """The scene reference as Markdown: every key of every table, with its unit, default and
    the validator's rules (``docs/scene-reference.md``)."""
    return _native.reference_text()


def engines() -> Dict[str, Path]:
    """The engine libraries this package carries and :meth:`Scene.package` embeds by default:
    ``{"linux64": .../libfmu_beam.so, "win64": .../fmu_beam.dll}`` (win64 only in a wheel built
    with the Windows toolchain)."""
    return {platform: Path(path) for platform, path in _native.engines().items()}


def main(argv: Optional[List[str]] = None) -> int:
    """The ``fmu-beam`` command (``argv`` without the program's name; default: ``sys.argv[1:]``):
    package, explain, modes, schema, reference, simulate, cosim, animate. Returns the exit
    status: 0 on success, 2 for a refused scene, 1 for another error. Run as the command (no
    ``argv``), an interrupt (Ctrl-C, SIGTERM) ends the process at once, as it ends
    ``fmu-harness``, with its temporary files removed."""
    as_command = argv is None
    args = sys.argv[1:] if as_command else list(argv)
    sys.stdout.flush()
    sys.stderr.flush()
    return _native.cli(["fmu-beam", *args], as_command=as_command)
