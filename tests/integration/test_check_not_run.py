"""A check that could not run is never reported as passed: target-contact on a recording
without a goal (no cube to touch) is ``n/a`` in the text, ``not_run`` in the JSON."""

from __future__ import annotations

import json

import pytest

from aou_dsl.cli.commands import main
from tests.conftest import BEHAVIOURS


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    """The same compiled motion as a CSV with its goal, and without it (a logged arm's)."""
    folder = tmp_path_factory.mktemp("notrun")
    with_goal = folder / "goal.csv"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "--no-check",
                 "-o", str(with_goal)]) == 0
    lines = with_goal.read_text().splitlines(keepends=True)
    assert any(line.startswith("# goal:") for line in lines)
    no_goal = folder / "nogoal.csv"
    no_goal.write_text("".join(x for x in lines if not x.startswith("# goal:")))
    return with_goal, no_goal


def test_target_contact_without_a_goal_is_not_a_pass(recordings, capsys):
    _, no_goal = recordings
    capsys.readouterr()
    assert main(["check", str(no_goal), "--robot", "panda", "--no-dynamic"]) == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines() if "target-contact" in line]
    assert [r[:2] for r in rows] == [["n/a", "target-contact"]]
    assert "no goal" in out and "target n/a" in out
    assert main(["check", str(no_goal), "--robot", "panda", "--no-dynamic",
                 "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert "target-contact" not in [c["name"] for c in doc["checks"]]
    assert [c["name"] for c in doc["not_run"]] == ["target-contact"]
    assert doc["ok"] is True and doc["clearances"]["target"] is None


def test_target_contact_with_a_goal_still_runs(recordings, capsys):
    with_goal, _ = recordings
    capsys.readouterr()
    assert main(["check", str(with_goal), "--robot", "panda", "--no-dynamic",
                 "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert "target-contact" in [c["name"] for c in doc["checks"]]
    assert "not_run" not in doc  # a report where every check ran is as before
    assert doc["clearances"]["target"] is not None
