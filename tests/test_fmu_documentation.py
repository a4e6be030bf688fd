"""Each packaged FMU's documentation/index.html (issue 16) lists its variables as its
modelDescription.xml declares them (read here by fmpy, as a master would): every variable once,
with its causality, variability, type, unit, start and meaning, inputs and outputs first; and it
still explains the resolved effects."""

import html.parser
import zipfile

import pytest
from fmpy import read_model_description

from conftest import packaged_fmus


class VariableRows(html.parser.HTMLParser):
    """The cells of the rows of `<table id="variables">`."""

    def __init__(self):
        super().__init__()
        self.inside, self.rows, self.cell = False, [], None

    def handle_starttag(self, tag, attrs):
        if tag == "table" and ("id", "variables") in attrs:
            self.inside = True
        elif self.inside and tag == "tr":
            self.rows.append([])
        elif self.inside and tag == "td":
            self.cell = ""

    def handle_endtag(self, tag):
        if tag == "table":
            self.inside = False
        elif self.inside and tag == "td":
            self.rows[-1].append(self.cell)
            self.cell = None

    def handle_data(self, data):
        if self.cell is not None:
            self.cell += data


def xml_start(v):
    if v.start is None:
        return ""
    return v.start


@pytest.mark.parametrize("fmu", packaged_fmus(), ids=lambda p: p.stem)
def test_documentation_lists_every_variable_of_the_model_description(fmu):
    with zipfile.ZipFile(fmu) as z:
        page = z.read("documentation/index.html").decode()
    parser = VariableRows()
    parser.feed(page)
    rows = [r for r in parser.rows if r]  # the header row has no <td>
    md = read_model_description(str(fmu))
    assert len(rows) == len(md.modelVariables)
    by_name = {r[0]: r for r in rows}
    assert len(by_name) == len(rows), "a variable is listed twice"
    for v in md.modelVariables:
        name, causality, variability, ty, unit, start, vr, meaning = by_name[v.name]
        assert (causality, variability, ty) == (v.causality, v.variability, v.type), v.name
        assert unit == (v.unit or ""), v.name
        assert start == xml_start(v), v.name
        assert int(vr) == v.valueReference, v.name
        assert meaning == v.description and meaning, v.name
    order = [{"input": 0, "output": 1}.get(r[1], 2) for r in rows]
    assert order == sorted(order), "inputs and outputs are listed before parameters"
    assert "<h2>Effects</h2>" in page


def test_an_fmu_with_inputs_documents_them(fmu_dir):
    """flexible_arm: its input torque, with unit and meaning, heads the table."""
    with zipfile.ZipFile(fmu_dir / "flexible_arm.fmu") as z:
        page = z.read("documentation/index.html").decode()
    parser = VariableRows()
    parser.feed(page)
    first = [r for r in parser.rows if r][0]
    assert first[:5] == ["hub.drive.torque", "input", "continuous", "Real", "N.m"], first
    assert "torque" in first[7]
