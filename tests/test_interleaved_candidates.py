"""The candidate rule of bench/peer/interleaved.py (issue 46): a cell is timed on each tool's
runs that meet its target for good within a margin of the cheapest, not on the sweep's one
choice. The script needs Exudyn to run; its rule is plain Python, tested here without it."""
import importlib.util
import sys
import types

from fmu_util import ROOT

SCRIPT = ROOT / "bench" / "peer" / "interleaved.py"


def load():
    # the script imports Exudyn's cases and sweep at its top: stand-ins, for the rule alone
    saved = {k: sys.modules.get(k) for k in ("exudyn_cases", "sweep")}
    sys.modules["exudyn_cases"] = types.ModuleType("exudyn_cases")
    sys.modules["sweep"] = types.ModuleType("sweep")
    try:
        spec = importlib.util.spec_from_file_location("interleaved_rule", SCRIPT)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    finally:
        for k, v in saved.items():
            if v is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = v


def point(formulation, setting, error, cpu, tool="fmu-beam"):
    return dict(tool=tool, case="c3_rigid", output="slider_position",
                formulation=formulation, setting=setting, error=error, cpu_median=cpu, steps=1)


def test_candidates_are_the_runs_meeting_the_target_within_the_margin_cheapest_first():
    il = load()
    points = [
        point("rod 2", "fixed step 1.0e-2 s", 9e-4, 0.0016),
        point("rod 2", "fixed step 5.0e-3 s", 2e-4, 0.0030),
        # within the margin of the cheapest, but its tighter step misses the target: not for good
        point("rod 3", "fixed step 1.0e-2 s", 9.5e-4, 0.0017),
        point("rod 3", "fixed step 5.0e-3 s", 1.2e-3, 0.0031),
        point("rod 4", "fixed step 1.0e-2 s", 8e-4, 0.0019),
        point("rod 5", "fixed step 1.0e-2 s", 8e-4, 0.0019),
        point("rod 6", "fixed step 1.0e-2 s", 8e-4, 0.0020),
        # another tool's run is never ours
        point("rod 2", "ne_rod=2;h=0.01", 1e-4, 0.0001, tool="exudyn"),
    ]
    runs = il.candidates(points, "fmu-beam", "c3_rigid", "slider_position", 1e-3, 1.25, 3)
    assert [(p["formulation"], p["cpu_median"]) for p in runs] == [
        ("rod 2", 0.0016), ("rod 4", 0.0019), ("rod 5", 0.0019)]
    # the margin bounds them: 1.1 x 0.0016 = 0.00176
    runs = il.candidates(points, "fmu-beam", "c3_rigid", "slider_position", 1e-3, 1.1, 3)
    assert [p["formulation"] for p in runs] == ["rod 2"]
    # a margin of 1 is the sweep's choice alone, as `fmu-bench peer` takes it: the cheapest
    # run that meets the target for good
    one = il.candidates(points, "fmu-beam", "c3_rigid", "slider_position", 1e-3, 1.0, 3)
    assert one == il.meeting(points, "fmu-beam", "c3_rigid", "slider_position", 1e-3)[:1]
    assert [p["formulation"] for p in one] == ["rod 2"]
    # a target nothing meets has no candidates
    assert il.candidates(points, "fmu-beam", "c3_rigid", "slider_position", 1e-6, 1.25, 3) == []
