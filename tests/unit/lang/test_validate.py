"""Stage 2: the IR holds SI values, defaults are filled, and the form is recorded."""

import dataclasses
import math

import pytest

from aou_dsl.core.robot_specs import ROBOTS
from aou_dsl.lang.ir import DEFAULTS, Effort, State
from aou_dsl.lang.linter import load
from tests.conftest import VALID


def _ok(text: str, path: str = "t.aou"):
    b, diags = load(text, path)
    assert b is not None, [d.message for d in diags]
    return b


def test_units_become_si():
    b = _ok((VALID / "units.aou").read_text())
    s = b.settings
    assert s.robot == "ur5" and s.start == pytest.approx(0.30) and s.standoff == pytest.approx(0.1)
    assert s.goal == pytest.approx((0.45, 0.15, 0.15))
    assert s.start_direction == pytest.approx((-0.6, 0.0, 0.8))  # normalised
    ap, pa, gh, gv, ti, sh = b.primitives
    assert ap.a == pytest.approx(0.09) and ap.v == pytest.approx(0.2)
    assert pa.duration == pytest.approx(1.25) and pa.count == 3
    assert gh.plane == "horizontal" and gh.angle == pytest.approx(0.349)
    assert gh.v == pytest.approx(math.radians(30)) and gh.count == 2
    assert gv.angle == pytest.approx(math.radians(10)) and gv.v == pytest.approx(0.5)
    assert ti.angle == pytest.approx(math.radians(15))
    assert sh.amplitude == pytest.approx(math.radians(6)) and sh.f == 4 and sh.duration == 0.5
    assert b.name == "units-demo_1" and b.state is None


def test_header_optional_name_is_stem():
    b = _ok("approach", "some/dir/peek-2.aou")
    assert b.name == "peek-2" and b.state is None and b.header_span is None


def test_defaults_are_filled():
    b = _ok("approach; retreat 5cm; pause 1s x3; gaze vertical 10deg; shiver 3deg")
    ap, re_, pa, gz, sh = b.primitives
    assert ap.a == DEFAULTS["approach_a"] and ap.v == DEFAULTS["speed_cap"] and ap.length is None
    assert re_.a == DEFAULTS["retreat_a"]
    assert gz.v == DEFAULTS["gaze_v"]
    assert sh.f == DEFAULTS["shiver_f"] and sh.duration == DEFAULTS["shiver_duration"]


def test_sequence_form_keeps_order_and_signs():
    b = _ok((VALID / "peek.aou").read_text())
    assert b.form == "sequence" and b.state is State.CURIOUS
    kinds = [p.kind for p in b.primitives]
    assert kinds == ["approach", "pause", "gaze", "pause", "gaze", "pause", "approach"]
    assert b.primitives[0].length == pytest.approx(0.08)
    assert b.primitives[4].angle == pytest.approx(-math.radians(20))
    assert b.primitives[6].length is None


def test_x0_means_absent_but_valid():
    b = _ok("approach; pause 1s x0")
    assert b.primitives[1].count == 0


def test_ir_is_frozen_and_rejects_unknown_fields():
    b = _ok("pause 1s")
    with pytest.raises(dataclasses.FrozenInstanceError):
        b.primitives[0].duration = 2.0  # type: ignore[misc]
    with pytest.raises(TypeError, match="colour"):
        type(b.primitives[0])(span=b.span, duration=1.0, colour="red")


def test_ir_checks_what_code_builds_or_changes():
    """Nodes built or changed from Python get the types their fields declare, or an
    error naming the field: the API cannot make a node the compiler would misread."""
    b = _ok("approach a=0.1; pause 1s x2; gaze horizontal 20deg")
    approach, gaze = b.first("approach"), b.first("gaze")
    assert approach.replace(a=1).a == 1.0 and isinstance(approach.replace(a=1).a, float)
    with pytest.raises(TypeError, match=r"Approach\.a"):
        approach.replace(a="fast")
    with pytest.raises(TypeError, match=r"Approach\.count"):
        approach.replace(count=2.5)
    with pytest.raises(ValueError, match=r"Gaze\.plane"):
        gaze.replace(plane="diagonal")
    with pytest.raises(ValueError, match="Effort.W"):
        Effort(span=b.span, W=1.5, T=0, S=0, F=0)
    assert b.replace(state="hesitant").state is State.HESITANT
    assert b.replace(primitives=[gaze]).primitives == (gaze,)


def test_all_errors_are_reported_not_just_the_first():
    b, diags = load("pause 3m\nretreat 6\nrobot r2d2\n", "t.aou")
    assert b is None
    assert [d.code for d in diags] == ["V102", "V103", "V109"]


def test_unknown_robot_lists_valid_names():
    _, (d,) = load("robot kuka\napproach", "t.aou")
    assert d.code == "V109" and "panda" in d.message and "ur5" in d.message
    assert d.fields["valid"] == list(ROBOTS) and len(ROBOTS) >= 6


def test_missing_unit_says_which_units_fit():
    _, (d,) = load("pause 2", "t.aou")
    assert d.code == "V103" and "s, ms" in d.message and d.hint == "write e.g. `2s`"


def test_resource_bound_on_time_is_an_error_not_a_hang():
    _, diags = load("approach a=1e-6", "t.aou")
    assert [d.code for d in diags] == ["V110"]


def test_a_start_beyond_reach_is_refused_at_the_start_line():
    """`start 2m` puts the end-effector 2 m from the goal before anything moves: V119 on
    the `start` line, not a late IK failure."""
    _, diags = load("start 2m\napproach\npause 1s\n", "t.aou")
    assert [(d.code, d.span.line) for d in diags] == [("V119", 1)]


def test_retreats_that_carry_the_hand_too_far_are_refused():
    """Three 0.3 m retreats in a row end 1.1 m from the goal: V119, before compiling."""
    _, diags = load("approach a=0.1; pause 1s x4; retreat 0.3m x3", "t.aou")
    assert "V119" in {d.code for d in diags}
