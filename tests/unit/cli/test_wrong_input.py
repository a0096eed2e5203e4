"""Input that is not what a command reads: a trajectory given to lint, a line too long to
show whole. The report stays short and says what the file looks like."""

from __future__ import annotations

import json

from aou_dsl.cli.report import EXCERPT, format_text
from aou_dsl.core.diagnostics import Span, diag
from aou_dsl.lang.linter import lint_file


def test_a_trajectory_given_to_lint_is_named_as_one(tmp_path):
    path = tmp_path / "hesitant.json"
    path.write_text(json.dumps({"format": "aou-trajectory/1", "q": [[0.0] * 7] * 20000}))
    res = lint_file(str(path))
    assert not res.ok
    first = res.diagnostics[0]
    assert "trajectory" in (first.hint or "") and "aouc measure" in first.hint
    text = format_text(first, path.read_text())
    assert len(text) < 3 * EXCERPT + 400  # not the whole megabyte line


def test_a_behaviour_with_a_mistake_gets_no_trajectory_hint(tmp_path):
    path = tmp_path / "b.aou"
    path.write_text("approach; paws 1s\n")
    res = lint_file(str(path))
    assert not res.ok and all("trajectory" not in (d.hint or "") for d in res.diagnostics)


def test_a_long_line_is_shown_around_the_column_with_the_caret_under_it():
    line = "a" * 3000 + "WRONG" + "b" * 3000
    d = diag("S001", "unexpected", Span("t.aou", 1, 3001, 1, 3006))
    shown, caret = format_text(d, line).splitlines()[1:3]
    assert "WRONG" in shown and len(shown) < EXCERPT + 20
    at = caret.index("^")
    assert shown[at:at + 5] == "WRONG" and caret.count("^") == 5


def test_a_short_line_is_shown_whole():
    d = diag("S001", "unexpected", Span("t.aou", 1, 11, 1, 15))
    shown, caret = format_text(d, "approach; paws 1s").splitlines()[1:3]
    assert shown.endswith("approach; paws 1s")
    assert shown[caret.index("^"):caret.index("^") + 4] == "paws"


def test_a_quantity_of_the_wrong_kind_is_named_with_its_article():
    from aou_dsl.lang.linter import load

    _, diags = load("gaze horizontal 20m\npause 1s x2\napproach a=3deg\n", "t.aou")
    messages = " / ".join(d.message for d in diags)
    assert "expected an angle" in messages and "found an angle" in messages
    assert "expected an acceleration" in messages and "found a length" in messages
    assert " a angle" not in messages and " a acceleration" not in messages
