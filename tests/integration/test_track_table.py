"""The tracking figures in docs/checks.md and docs/robots.md are what
tools/track_table.py computes from the code now: two rows recomputed (the whole table
is `python tools/track_table.py --check`, minutes of compiles)."""

import sys

import pytest

pytest.importorskip("mujoco")

from tests.conftest import BEHAVIOURS, ROOT  # noqa: E402

sys.path.insert(0, str(ROOT / "tools"))
import track_table  # noqa: E402


def _table(path) -> list[str]:
    text = path.read_text(encoding="utf-8")
    assert track_table.START in text and track_table.END in text, path
    body = text[text.index(track_table.START):text.index(track_table.END)]
    return [ln for ln in body.splitlines() if ln.startswith("| `")]


@pytest.mark.parametrize(("robot", "name"), [("panda", "fearful"), ("ur5", "inactive"),
                                             ("kinova", "fearful")])
def test_a_row_of_the_checks_page_is_its_recomputation(robot, name):
    """Fearful on the Panda (its shiver shrinks under plain set-points), inactive on
    the UR5 (a 500 Hz controller without computed torque) and fearful on the Kinova
    (refused even fitted: its motion as declared, a what-if): the page's row is the row
    the script writes from a new tracking."""
    path = BEHAVIOURS / f"{name}.aou"
    report = track_table.track(path, robot)
    new = track_table.row(path, robot, report)
    rows = [ln for ln in _table(ROOT / "docs" / "checks.md")
            if ln.split(" | ")[0] in (f"| `{robot}`", f"| `{robot}` (generic servo)")
            and ln.split(" | ")[1].split(",")[0].split(" (")[0] == name]
    assert rows == [new]
    if robot == "panda":  # the figure the page's prose quotes
        assert "shiver 54 %" in track_table.cell(report, "position")
    if robot == "kinova":  # refused: tracked as declared, and labelled so
        assert "what-if" in new and report.what_if is not None
        assert "shiver 54 %" in track_table.cell(report.what_if, "position")


def test_the_tables_cover_every_shipped_behaviour_on_every_arm_with_a_servo_table():
    from aou_dsl.core.robot_specs import ROBOTS
    from aou_dsl.core.servo_specs import servo_table

    with_table = [r for r in ROBOTS if servo_table(r) is not None]
    assert {"panda", "ur5"} <= set(with_table)
    rows = _table(ROOT / "docs" / "checks.md")
    for robot in with_table:
        for path in sorted(BEHAVIOURS.glob("*.aou")):
            assert sum(ln.startswith(f"| `{robot}` | {path.stem}") for ln in rows) == 1, \
                (robot, path.stem)
    arms = _table(ROOT / "docs" / "robots.md")
    # an arm's cell is its name, then the behaviours it refuses even fitted
    assert [ln.split(" |")[0][2:].split(";")[0] for ln in arms if "generic" not in ln] == \
        [f"`{r}`" for r in with_table]
