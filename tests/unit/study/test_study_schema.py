"""The study file's JSON Schema (`aou_dsl/schemas/study.schema.json`): the file `aouc
study init` writes and the documented example validate, and every broken study file of
the table below, which `aouc study` refuses with E701, is refused by the schema too."""

from __future__ import annotations

import json
import re
import tomllib
from importlib import resources
from pathlib import Path

import jsonschema
import pytest

from aou_dsl.core.diagnostics import AouError
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.ir import State
from aou_dsl.study.init import init_study
from aou_dsl.study.spec import read_study

DOCS = Path(__file__).resolve().parents[3] / "docs" / "study.md"

#: Broken study files: (what, the text of `aouc study init`'s file -> the broken text).
#: Each edit must change the file (a test below checks it), and aou refuses the result.
BROKEN = {
    "an unknown key": lambda t: t.replace("[study]\n", "[study]\ncolour = \"red\"\n"),
    "an unknown table": lambda t: t + "\n[extras]\nx = 1\n",
    "Part A missing": lambda t: t.replace("[part_a]\n", "[part_c]\n"),
    "a seed that is a text": lambda t: re.sub(r"(?m)^seed = \d+", 'seed = "1"', t),
    "a negative seed": lambda t: re.sub(r"(?m)^seed = \d+", "seed = -3", t),
    "an intensity of 12 points": lambda t: re.sub(r"(?m)^intensity = \d+", "intensity = 12",
                                                  t),
    "an intensity of 1 point": lambda t: re.sub(r"(?m)^intensity = \d+", "intensity = 1", t),
    "an intensity that is a number with a fraction": lambda t: re.sub(
        r"(?m)^intensity = \d+", "intensity = 4.5", t),
    "a width that is a truth value": lambda t: re.sub(r"(?m)^width = \d+", "width = true", t),
    "a frame rate of 0": lambda t: re.sub(r"(?m)^fps = \d+", "fps = 0", t),
    "others that is a text": lambda t: re.sub(r"(?m)^others = \w+", 'others = "yes"', t),
    "a state the model does not have": lambda t: t.replace(
        'states = ["confident"', 'states = ["sleepy", "confident"'),
    "a state twice": lambda t: t.replace('states = ["confident"',
                                         'states = ["confident", "confident"'),
    "no state": lambda t: re.sub(r"(?m)^states = \[.*\]$", "states = []", t),
    "thirteen Part A behaviours": lambda t: re.sub(
        r"(?m)^behaviours = \[.*\]$",
        "behaviours = [" + ", ".join(['"behaviours/curious.aou"'] * 13) + "]", t),
    "a pair missing its high": lambda t: re.sub(r", high = [-\d.e]+", "", t, count=1),
    "a pair missing its behaviour": lambda t: re.sub(r'behaviour = "[^"]*", ', "", t,
                                                     count=1),
    "a pair with a key of its own": lambda t: t.replace(", high =", ", colour = 1, high =", 1),
    "a pair of an unknown descriptor": lambda t: re.sub(r'descriptor = "\w+"',
                                                        'descriptor = "speed"', t, count=1),
    "a pair whose low is a text": lambda t: re.sub(r"low = [-\d.e]+", 'low = "0.5"', t,
                                                   count=1),
    "an attention check of one option": lambda t: t + (
        '\n[[attention.checks]]\nquestion = "Sky?"\noptions = ["blue"]\nanswer = "blue"\n'),
    "an attention check without its answer": lambda t: t + (
        '\n[[attention.checks]]\nquestion = "Sky?"\noptions = ["blue", "red"]\n'),
    "an attention table with a key of its own": lambda t: t + "\n[attention]\nevery = 3\n",
    "a completion key of its own": lambda t: t + '\n[completion]\nurl = "https://x"\n',
    "a consent that is a list": lambda t: re.sub(r'(?s)consent = """.*?"""',
                                                 'consent = ["yes"]', t),
    "a title of 20,001 characters": lambda t: re.sub(r"(?m)^title = .*$",
                                                     f'title = "{"x" * 20_001}"', t),
}


@pytest.fixture(scope="module")
def validator() -> jsonschema.Draft202012Validator:
    body = json.loads((resources.files("aou_dsl") / "schemas" / "study.schema.json")
                      .read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(body)
    return jsonschema.Draft202012Validator(body)


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("schema")
    init_study(str(folder / "s"))
    return folder / "s" / "study.toml"


def _errors(validator, text: str) -> list[str]:
    return [e.message for e in validator.iter_errors(tomllib.loads(text))]


def test_the_study_init_writes_validates(validator, written):
    text = written.read_text()
    read_study(str(written))  # aou reads it
    assert _errors(validator, text) == []


def test_the_documented_example_validates(validator):
    """The study file shown in docs/study.md."""
    blocks = re.findall(r"(?s)```toml\n(.*?)```", DOCS.read_text())
    example = next(b for b in blocks if "[part_a]" in b)
    assert _errors(validator, example) == []


@pytest.mark.parametrize("what", BROKEN)
def test_a_file_aou_refuses_the_schema_refuses(validator, written, what, tmp_path):
    good = written.read_text()
    bad = BROKEN[what](good)
    assert bad != good, "the edit did not apply: the file init writes changed"
    path = written.parent / f"broken-{abs(hash(what))}.toml"
    path.write_text(bad)
    try:
        with pytest.raises(AouError) as err:
            read_study(str(path))
    finally:
        path.unlink()
    assert err.value.diagnostics[0].code == "E701", err.value.diagnostics[0].message
    assert _errors(validator, bad), what


def test_the_schema_names_the_states_and_descriptors_aou_knows(validator):
    defs = validator.schema["$defs"]
    assert defs["state"]["enum"] == [s.value for s in State]
    assert defs["descriptor"]["enum"] == list(REGISTRY)
