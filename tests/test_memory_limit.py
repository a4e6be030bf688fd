"""A unit that cannot have the memory its scene needs refuses with a message instead of taking
the master's process down (issue 35): fmi2ExitInitializationMode reserves the scene's estimate
before building (fmu-beam/src/unit/memory.rs). The master runs in a child process whose address
space is limited (RLIMIT_AS, as `ulimit -v` or a batch system sets it) to what it already uses
plus 400 MiB, and the scene's unit needs about 700 MiB (1000 planar elements in one frame: 712
MB of peak resident memory measured when it runs unlimited). Without the reservation the build's
own allocations fail and Rust aborts the process (SIGABRT)."""

import json
import subprocess
import sys
import textwrap

from fmu_util import ROOT

SCENE = """
name = "big_cantilever"

[experiment]
stop_time = 0.002
step_size = 1e-3

[solver]
adaptive = false
max_step = 5e-4

[[beam]]
name = "beam"
length = 2.0
elements = 1000
frame = "tangent"
material = { rho = 2700.0, E = 72e9 }
section = { shape = "rectangle", a = 0.01, b = 0.01 }
outputs = ["tip.deflection"]

[[joint]]
name = "clamp"
type = "weld"
frames = ["world", "beam.a"]
"""

MASTER = textwrap.dedent(
    """
    import json, re, resource, sys
    sys.path.insert(0, sys.argv[2])
    from fmpy import extract, read_model_description
    from fmpy.fmi1 import FMICallException
    from fmu_util import Instance

    fmu = sys.argv[1]
    md = read_model_description(fmu)
    inst = Instance(extract(fmu), md)
    inst.fmu.setupExperiment(startTime=0.0)
    inst.fmu.enterInitializationMode()
    used = int(re.search(r"VmSize:\\s+(\\d+) kB", open("/proc/self/status").read()).group(1)) * 1024
    resource.setrlimit(resource.RLIMIT_AS, (used + (400 << 20), resource.RLIM_INFINITY))
    try:
        inst.fmu.exitInitializationMode()
        outcome = "initialized"
    except FMICallException as e:
        outcome = f"refused: {e}"
    inst.close()
    print(json.dumps({"outcome": outcome, "errors": inst.logger.errors()}))
    """
)


def test_a_unit_that_cannot_have_its_memory_refuses_and_the_master_survives(harness, root, tmp_path):
    engine = root / "target" / "release" / "libfmu_beam.so"
    scene = tmp_path / "big_cantilever.toml"
    scene.write_text(SCENE)
    fmu = tmp_path / "big_cantilever.fmu"
    packaged = subprocess.run(
        [str(harness), "package", str(scene), "-o", str(fmu), "--binary", f"linux64={engine}"],
        capture_output=True,
        text=True,
    )
    assert packaged.returncode == 0, packaged.stderr
    run = subprocess.run(
        [sys.executable, "-c", MASTER, str(fmu), str(ROOT / "tests")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, f"the master's process ended with {run.returncode}: {run.stderr[-2000:]}"
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert result["outcome"].startswith("refused"), result
    message = " ".join(result["errors"])
    assert "initialization: the unit needs about" in message and "MiB of memory" in message, message
