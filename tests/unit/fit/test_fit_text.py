"""The fit's one rounding rule, its one pattern of a number with its unit and its one
way to change a value in a statement, against values worked out by hand."""

from __future__ import annotations

import random

import pytest

from aou_dsl.core.diagnostics import Span
from aou_dsl.fit.quantity import first, keyed
from aou_dsl.fit.rounding import significant, written
from aou_dsl.fit.text_edits import Change, apply, set_value


@pytest.mark.parametrize(("x", "digits", "toward", "value", "text"), [
    (2.2734, 2, "down", 2.2, "2.2"),
    (2.2, 2, "down", 2.2, "2.2"),            # stored a little under 2.2: kept
    (84.999, 2, "down", 84.0, "84"),
    (0.0123456, 3, "down", 0.0123, "0.0123"),
    (1234567.0, 4, "down", 1234000.0, "1234000"),  # no exponent
    (2.2001, 3, "up", 2.21, "2.21"),
    (2.2, 3, "up", 2.2, "2.2"),              # exact: not raised
    (9.996, 3, "up", 10.0, "10"),
    (2.25, 2, "nearest", 2.2, "2.2"),        # as printed: half to even on the stored value
    (2.26, 2, "nearest", 2.3, "2.3"),
])
def test_rounding_to_significant_digits(x, digits, toward, value, text):
    assert significant(x, digits, toward) == value
    assert written(x, digits, toward) == text


def test_rounding_keeps_order_in_every_direction():
    """A variant pair keeps its order: rounding is monotone (never reversed)."""
    rnd = random.Random(5)
    xs = sorted(10 ** rnd.uniform(-3, 3) for _ in range(2000))
    for toward in ("down", "up", "nearest"):
        ys = [significant(x, 3, toward) for x in xs]
        assert ys == sorted(ys), toward


def test_a_value_under_zero_or_not_finite_rounds_to_nothing():
    assert significant(0.0, 3) == 0.0 and significant(-1.0, 3, "up") == 0.0
    assert significant(float("inf"), 3) == 0.0
    assert written(0.0, 3) == "0"


@pytest.mark.parametrize(("stmt", "dimension", "found"), [
    ("gaze horizontal 60deg", None, ("60", "deg")),
    ("retreat 5mm a=2", None, ("5", "mm")),          # `5mm` is not `5m` and `m`
    ("retreat -0.2m", "length", ("-0.2", "m")),
    ("tilt 20deg v=30deg/s", "angle", ("20", "deg")),
    ("shiver 6deg f=2.5Hz for 2s", "length", None),
    ("approach a=0.1", None, None),                   # a keyed value is not positional
    ("gaze vertical 1e1deg", "angle", ("1e1", "deg")),
])
def test_the_first_positional_quantity(stmt, dimension, found):
    m = first(stmt, dimension)
    assert (None if m is None else (m["number"], m["unit"])) == found


def test_keyed_values_of_an_edit():
    assert keyed("f=1.4Hz for 2.15s") == [("f", "1.4", "Hz"), ("for", "2.15", "s")]
    assert keyed("a=1.2") == [("a", "1.2", "")]


@pytest.mark.parametrize(("stmt", "key", "value", "after"), [
    ("shiver 6deg f=2.5Hz", "f", "f=1.4Hz", "shiver 6deg f=1.4Hz"),
    ("shiver 6deg", "f", "f=1.4Hz", "shiver 6deg f=1.4Hz"),           # added after its value
    ("gaze horizontal 60deg x2", "angle", "46.1deg", "gaze horizontal 46.1deg x2"),
    ("gaze horizontal 60deg", "v", "v=20deg/s", "gaze horizontal 60deg v=20deg/s"),
    ("approach", "a", "a=0.5", "approach a=0.5"),
    ("shiver 6deg for 2s", "for", "for 3.1s", "shiver 6deg for 3.1s"),
    ("shiver 6deg f=2Hz", "a", "a=1", "shiver 6deg a=1 f=2Hz"),
])
def test_one_value_set_in_a_statement(stmt, key, value, after):
    assert set_value(stmt, key, value) == after


def test_changes_in_two_statements_of_one_line_keep_their_places():
    text = "behaviour b\npause 1s; shiver 6deg f=2.5Hz; tilt 20deg\n"
    shiver = Span("b.aou", 2, 11, 2, 30)
    tilt = Span("b.aou", 2, 32, 2, 42)
    out = apply(text, [Change(shiver, "f", "2.5", "1.2", "Hz"),
                       Change(tilt, "v", "", "15", "deg/s")])
    assert out == "behaviour b\npause 1s; shiver 6deg f=1.2Hz; tilt 20deg v=15deg/s\n"
