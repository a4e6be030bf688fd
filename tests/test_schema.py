"""The scene schema (scenes/scene.schema.json, `fmu-harness schema`) against the scenes (issue 16).

Every shipped scene validates against it and names it on its first line (what Taplo-based
editors read); every scene of tests/refused_scenes.toml whose rule the schema expresses
(`schema = true`, which fmu-beam/tests/scene_rules.rs checks against the rule table) is refused
by it, and the others are accepted: the schema flags no scene that the engine would take for
that reason. That the committed file is what the code generates is checked by
fmu-harness/tests/generated_docs.rs.
"""

import copy
import json
import math
import pathlib
import tomllib

import jsonschema
import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCENES = ROOT / "scenes"
SCHEMA_LINE = "#:schema ./scene.schema.json"


@pytest.fixture(scope="module")
def validator():
    schema = json.loads((SCENES / "scene.schema.json").read_text())
    jsonschema.Draft7Validator.check_schema(schema)
    return jsonschema.Draft7Validator(schema)


def problems(validator, doc):
    return [f"{'.'.join(map(str, e.absolute_path)) or '<scene>'}: {e.message}"
            for e in validator.iter_errors(doc)]


SHIPPED = sorted(SCENES.glob("*.toml"))


def test_there_are_scenes_to_check():
    assert len(SHIPPED) >= 20


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_every_shipped_scene_validates_and_names_the_schema(validator, path):
    text = path.read_text()
    assert text.splitlines()[0] == SCHEMA_LINE, f"{path.name}: first line is not {SCHEMA_LINE!r}"
    assert problems(validator, tomllib.loads(text)) == []


CASES = tomllib.loads((ROOT / "tests" / "refused_scenes.toml").read_text())


def slot(doc, path):
    """The container and key of a dotted path (`beam.0.section.A`), tables created as needed."""
    keys = path.split(".")
    cur = doc
    for k in keys[:-1]:
        if isinstance(cur, list):
            i = int(k)
            if i == len(cur):
                cur.append({})
            cur = cur[i]
        else:
            cur = cur.setdefault(k, {})
    last = keys[-1]
    if isinstance(cur, list):
        last = int(last)
        if last == len(cur):
            cur.append(None)
    return cur, last


def scene_of(case):
    """The scene of a refused_scenes.toml entry: its base with `unset` and `set` applied, as
    fmu-beam/tests/scene_rules.rs builds it."""
    doc = copy.deepcopy(tomllib.loads(CASES["base"][case.get("base", "planar")]))
    for path in case.get("unset", []):
        parent, key = slot(doc, path)
        parent.pop(key, None)
    for path, value in case.get("set", {}).items():
        parent, key = slot(doc, path)
        parent[key] = value
    for path, length in case.get("repeat", {}).items():
        parent, key = slot(doc, path)
        items = parent[key]
        while len(items) < length:
            item = copy.deepcopy(items[-1])
            if isinstance(item, dict) and isinstance(item.get("name"), str):
                item["name"] = f"{item['name']}_{len(items)}"
            items.append(item)
    return doc


def non_finite(value):
    if isinstance(value, float):
        return not math.isfinite(value)
    if isinstance(value, list):
        return any(non_finite(v) for v in value)
    if isinstance(value, dict):
        return any(non_finite(v) for v in value.values())
    return False


def test_the_base_scenes_validate(validator):
    for name, text in CASES["base"].items():
        assert problems(validator, tomllib.loads(text)) == [], name


REFUSED = CASES["refused"]


@pytest.mark.parametrize("k", range(len(REFUSED)),
                         ids=[f"{k}-{c['rule']}" for k, c in enumerate(REFUSED)])
def test_the_schema_refuses_what_it_can_express(validator, k):
    case = REFUSED[k]
    found = problems(validator, scene_of(case))
    if case.get("schema", False):
        assert found, f"entry {k} (rule {case['rule']}): the schema accepts a scene the engine refuses"
    elif non_finite(case.get("set", {})):
        # JSON has no NaN or infinity: a JSON-Schema validator's comparisons with them are
        # meaningless, and the schema claims nothing about them (rule `finite`).
        pass
    else:
        assert found == [], (
            f"entry {k} (rule {case['rule']}): the schema refuses a scene for a reason the rule "
            f"table does not give it: {found}")


def test_the_schema_describes_units_and_rules():
    schema = json.loads((SCENES / "scene.schema.json").read_text())
    length = schema["definitions"]["BeamSpec"]["properties"]["length"]
    assert length["x-unit"] == "m"
    assert "Unit: m." in length["description"]
    assert "must be positive (positive)" in length["description"]
    assert length["exclusiveMinimum"] == 0
