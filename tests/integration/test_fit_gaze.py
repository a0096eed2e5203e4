"""`--fit` never writes a value the language refuses: a gaze short of its angular
acceleration (C304) is not given `a=` (a gaze takes no such key, V112: its acceleration
is the language's own), the fit leaves it with a C314 that says why, typed, and fits the
rest of the file still.

The oracle is the language itself: every fitted text is linted again here, and read
statement by statement for an `a=` in a gaze."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from aou_dsl.core.codes import C304, C314
from aou_dsl.core.diagnostics import Severity
from aou_dsl.driver.builder import build_file
from aou_dsl.fit.refusals import FixedByLanguage
from aou_dsl.lang.linter import lint_source
from aou_dsl.lang.primitives import APPROACH, GAZE

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def slow_wrist(tmp_path_factory) -> str:
    """A UR5 whose joints accelerate at 0.2 rad/s^2: too little for a gaze's 45 deg/s^2
    (the wrist reaches about 0.12 rad/s^2 of it) and for the curious approach."""
    p = tmp_path_factory.mktemp("robot") / "slow.toml"
    p.write_text('robot = "ur5"\njoint_accel = 0.2\njoint_jerk = 1000.0\n')
    return str(p)


def _gaze_keys(text: str) -> list[str]:
    """Every gaze statement of ``text`` that writes `a=`."""
    out = []
    for row in text.split("\n"):
        for stmt in row.split("#")[0].split(";"):
            words = stmt.split()
            if words and words[0] == GAZE and any(w.startswith("a=") for w in words):
                out.append(stmt.strip())
    return out


def _fitted(path: str, robot: str):
    res = build_file(path, robot=robot, fit=True, check=False)
    text = res.fitted_source or Path(path).read_text()
    return res, text


def test_the_curious_gaze_short_of_its_acceleration_is_left_and_said_why(slow_wrist):
    path = str(ROOT / "behaviours" / "curious.aou")
    plain = build_file(path, robot=slow_wrist, fit=False, check=False)
    short = [d for d in plain.diagnostics if d.code == C304 and d.span.line == 7]
    assert short, "the reproducing case no longer refuses the gaze's acceleration"
    res, text = _fitted(path, slow_wrist)
    assert res.fitted_source is not None, [d.message for d in res.diagnostics]
    again = lint_source(text, path)
    assert again.ok, [d.message for d in again.diagnostics]
    assert not _gaze_keys(text)
    # the approach is fitted: the gaze's refusal does not stop the rest
    approach = next(r for r in text.split("\n") if r.startswith(APPROACH))
    assert approach != "approach a=0.09" and float(approach.split("a=")[1]) < 0.09
    said = [d for d in res.diagnostics if d.code == C314 and d.span.line == 7]
    assert len(said) == 1 and isinstance(said[0].refusal, FixedByLanguage), said
    r = said[0].refusal
    assert r.kind == GAZE and r.key == "a" and "a" not in r.takes
    assert "fixed by the language" in said[0].message and "V112" not in said[0].message
    assert said[0].fields["key"] == "a"


CASES = [
    ("behaviours/curious.aou", "slow"),
    ("tests/valid/peek.aou", "slow"),
    ("tests/valid/units.aou", "ur5"),
    ("tests/valid/units.aou", "xarm7"),
    ("behaviours/fearful.aou", "kinova"),
]


@pytest.mark.parametrize(("rel", "robot"), CASES)
def test_no_fitted_output_writes_a_key_the_language_refuses(rel, robot, slow_wrist):
    """Shipped files the arms refuse something of: what the fit writes lints clean, no
    gaze gets `a=`, and no refusal of the fit is the language's."""
    path = str(ROOT / rel)
    res, text = _fitted(path, slow_wrist if robot == "slow" else robot)
    assert not _gaze_keys(text)
    again = lint_source(text, path)
    assert not [d for d in again.diagnostics if d.severity is Severity.ERROR]
    refused = [d.message for d in res.diagnostics if d.code == C314
               and re.search(r"\bV\d{3}\b", d.message)]
    assert not refused, refused
