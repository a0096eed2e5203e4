"""Lint's bounds agree with what compile and measure can show: a motion lint accepts is
one the measured motion shows, and one it refuses says why at the place to change.

- V123: a move along the line of sight under 5 mm, whichever word and sign wrote it (an
  approach of -3 mm is a 3 mm retreat), or made by the layout (the rest of the way to the
  standoff, the pieces of a descriptor-form approach).
- V121: when no episode of a statement can count, the message says why in words.
- V116: a repeat count is a whole number >= 0, reported at the count as written.
- C301/C302: a start pose out of reach is blamed on what sets it (the `start` line).
- Layout: tilts alternate in the order they run, so the roll stays between the start's
  and one tilt angle away.
"""

import math
import re

import pytest

from aou_dsl.driver.builder import build_source
from aou_dsl.lang.descriptors import compare
from aou_dsl.lang.linter import lint_source
from tests import langgen


def _lint(text: str):
    return lint_source(text, "t.aou")


def _errors(res) -> list:
    return [d for d in res.diagnostics if d.severity == "error"]


def _codes(res) -> set[str]:
    return {d.code for d in _errors(res)}


def _at(text: str, d) -> str:
    """The source text a diagnostic's span covers (one line)."""
    line = text.split("\n")[d.span.line - 1]
    return line[d.span.col - 1:d.span.end_col - 1]


def _round_trip(text: str):
    """Build without the safety checks; the mismatches of measured against declared."""
    res = build_source(text, "t.aou", check=False)
    assert res.ok, [(d.code, d.message) for d in res.diagnostics]
    return res, compare(res.document["descriptors"]["declared"], res.measured.descriptors)


# --- V123: moves along the line of sight --------------------------------------------------

SHORT_MOVES = ["approach 1mm", "approach 2mm", "approach 4.9mm", "approach -3mm",
               "retreat 3mm", "retreat -3mm", "approach 0.4cm", "retreat -0.004m"]


@pytest.mark.parametrize("move", SHORT_MOVES)
def test_a_move_under_5mm_is_refused_at_its_length(move):
    """Either word, either sign: what counts is how far the end-effector moves."""
    text = f"sequence {{ pause 0.5s; {move}; pause 0.5s }}\n"
    res = _lint(text)
    (d,) = _errors(res)
    assert d.code == "V123", d.message
    assert _at(text, d) == move.split()[1]


@pytest.mark.parametrize("move", ["approach 5mm", "approach -5mm", "retreat 5mm",
                                  "retreat -5mm"])
def test_the_smallest_accepted_move_measures_as_declared(move):
    """5 mm either way between two pauses: two pauses are measured (the move keeps them
    apart) and the move is measured as the approach or retreat it is."""
    res, mismatches = _round_trip(f"sequence {{ pause 0.5s; {move}; pause 0.5s }}\n")
    assert mismatches == []
    m = res.measured.descriptors
    assert m["pause_count"] == 2
    toward = (move.split()[0] == "approach") == (not move.split()[1].startswith("-"))
    assert (m["approach_acceleration"] is not None) == toward
    assert m["retreat_count"] == (0 if toward else 1)


def test_an_approach_to_the_standoff_that_is_too_short_is_refused():
    """Default standoff 0.10 m, start 0.30 m: after 0.197 m, 3 mm are left."""
    text = "sequence { approach 0.197m; pause 1s; approach; pause 1s }\n"
    (d,) = _errors(_lint(text))
    assert d.code == "V123" and _at(text, d) == "approach"
    assert "3 mm" in d.message
    ok = "sequence { approach 0.19m; pause 1s; approach; pause 1s }\n"
    assert _errors(_lint(ok)) == []


def test_descriptor_approach_pieces_too_short_are_refused_and_the_hint_works():
    """Two gazes and an end hold make three pieces of 10 mm / 3: too short. The hint's
    start, applied, gives pieces that lint accepts and the round trip shows."""
    text = ("start 0.13m\nstandoff 0.12m\npause 1s x3\napproach\n"
            "gaze horizontal 20deg x2\n")
    (d,) = _errors(_lint(text))
    assert d.code == "V123" and d.span.line == 4
    m = re.search(r"`start (\d+)cm`", d.hint or "")
    assert m, d.hint
    fixed = text.replace("start 0.13m", f"start {m.group(1)}cm")
    assert _errors(_lint(fixed)) == []
    _, mismatches = _round_trip(fixed)
    assert mismatches == []


# --- V121 in words -----------------------------------------------------------------------

V121_CASES = [
    ("approach\npause 1s x0\nretreat 3cm\n", 3, "retreat", "no pause"),
    ("pause 1s\nretreat 3cm\napproach\n", 2, "retreat", "only one pause"),
    ("gaze horizontal 20deg\npause 1s x0\n", 1, "gaze", "no pause"),
    ("approach\ngaze horizontal 20deg x2\n", 2, "gaze", "no pause"),
]


@pytest.mark.parametrize(("text", "line", "kind", "why"), V121_CASES)
def test_v121_says_why_no_episode_counts(text, line, kind, why):
    """One diagnostic for the statement, at it, saying why none of its episodes counts
    (not a missing value printed as `None`)."""
    errors = _errors(_lint(text))
    assert [d.code for d in errors] == ["V121"], [d.message for d in errors]
    d = errors[0]
    assert d.span.line == line
    assert "None" not in d.message
    assert f"show a {kind}" in d.message and why in d.message


def test_v121_counts_still_say_how_many():
    (d,) = _errors(_lint("pause 2s x2\napproach\nretreat 3cm x3\n"))
    assert d.code == "V121"
    assert "retreat_count is declared 3" in d.message and "shows 1" in d.message
    assert "at least 4 pauses" in d.message  # the need that stops it, by counting


# --- V116: what a repeat count is --------------------------------------------------------

BAD_COUNTS = [("x1.5", "`x1` or `x2`"), ("x-1", "`x0`"), ("x-1.5", "`x0`"),
              ("x+2", "`x2`"), ("x0.5", "`x1`"), ("x3.0", "`x3`"), ("x2b", "`x2`"),
              ("x -1", "`x0`")]


@pytest.mark.parametrize(("count", "hint"), BAD_COUNTS)
@pytest.mark.parametrize("form", ["descriptor", "sequence"])
def test_a_count_that_is_not_a_whole_number_is_v116_at_the_count(count, hint, form):
    stmt = f"pause 1s {count}"
    text = (f"{stmt}\ngaze horizontal 20deg\n" if form == "descriptor" else
            f"sequence {{\n  {stmt}\n  gaze horizontal 20deg\n  pause 1s\n}}\n")
    (d,) = _errors(_lint(text))
    assert d.code == "V116", d.message
    assert _at(text, d) == count
    assert "whole number" in d.message and hint in (d.hint or "")


@pytest.mark.parametrize(("count", "fixed"), [("x1.5", "x2"), ("x-1", "x0"), ("x+2", "x2")])
def test_the_count_hint_applied_lints_clean(count, fixed):
    text = f"sequence {{\n  gaze horizontal 20deg\n  pause 1s {count}\n  gaze horizontal 0deg\n}}\n"
    d = _errors(_lint(text))[0]
    assert f"`{fixed}`" in (d.hint or "")
    assert _errors(_lint(text.replace(count, fixed))) == []


def test_a_count_apart_from_its_x_is_still_the_spacing_slip():
    text = "pause 1s x 3\ngaze horizontal 20deg\n"
    (d,) = _errors(_lint(text))
    assert d.code == "V113" and "x3" in (d.hint or "")


# --- C301/C302: the start pose -----------------------------------------------------------

UNREACHABLE_STARTS = [
    ("robot ur3\nstart 50cm\napproach\npause 1s\n", "C301"),
    ("robot ur3\nstart 50cm\nsequence { approach 0.3m; pause 1s }\n", "C301"),
    ("robot z1\nstart 50cm\npause 1s\ngaze horizontal 10deg\n", "C302"),
]


@pytest.mark.parametrize(("text", "code"), UNREACHABLE_STARTS)
def test_an_unreachable_start_points_at_the_start_line_and_the_hint_reaches(text, code):
    """50 cm from the arm's default goal is out of its reach: the `start` line is to
    blame, not the first statement; at the start the hint gives, every pose of the
    motion is reached (no C301-C303 at all)."""
    res = build_source(text, "t.aou", check=False)
    (d,) = [x for x in res.diagnostics if x.code in ("C301", "C302", "C303")]
    assert d.code == code and d.span.line == 2
    assert "start pose" in d.message and "`start`" in d.message
    m = re.search(r"`start (\d+)cm`", d.hint or "")
    assert m, d.hint
    fixed = text.replace("start 50cm", f"start {m.group(1)}cm")
    again = build_source(fixed, "t.aou", check=False)
    assert not [(x.code, x.message) for x in again.diagnostics
                if x.code in ("C301", "C302", "C303")]


def test_an_unreachable_default_start_says_it_is_the_default():
    """No `start` line: the start pose is at the default distance, along the goal's line."""
    text = "robot ur3\ngoal (0.7, 0, 0.2)\napproach\npause 1s\n"
    res = build_source(text, "t.aou", check=False)
    (d,) = [x for x in res.diagnostics if x.code in ("C301", "C302", "C303")]
    assert d.span.line == 2
    assert "default start distance" in d.message and "0.3 m" in d.message


def test_a_goal_no_start_can_reach_is_blamed_on_the_goal():
    """With a `start` line too, a goal out of reach at every start distance is the goal's
    fault: the diagnostic points at it and the hint does not offer a start."""
    text = "start 25cm\ngoal (2.0, 0, 0.3)\napproach\npause 1s\n"
    res = build_source(text, "t.aou", check=False)
    (d,) = [x for x in res.diagnostics if x.code in ("C301", "C302", "C303")]
    assert d.code == "C301" and d.span.line == 2
    assert "`start " not in (d.hint or "") and "goal" in (d.hint or "")


# --- layout: tilts alternate in time -----------------------------------------------------

def _tilts(text: str) -> list:
    res = _lint(text)
    assert res.timeline is not None, [d.message for d in res.diagnostics]
    return list(res.timeline.episodes)


@pytest.mark.parametrize("n_tilts", [1, 2, 3, 4, 5])
def test_more_tilts_than_gazes_alternate_about_the_start(n_tilts):
    """`tilt 70deg x3` beside two gazes: +70, -70, +70 in time; never 140."""
    text = f"approach\npause 1s x3\ngaze horizontal 20deg x2\ntilt 70deg x{n_tilts}\n"
    eps = _tilts(text)
    tilts = [e for e in eps if e.kind == "tilt"]
    assert len(tilts) == n_tilts
    angle = math.radians(70)
    for n, e in enumerate(tilts):
        assert e.end.roll - e.start.roll == pytest.approx(angle if n % 2 == 0 else -angle)
        assert -1e-9 <= min(e.start.roll, e.end.roll)
        assert max(e.start.roll, e.end.roll) <= angle + 1e-9
    # a tilt comes before its stop's gaze: what follows a run of tilts is a gaze
    for i, e in enumerate(eps):
        if e.kind == "tilt" and eps[i + 1].kind != "tilt":
            assert eps[i + 1].kind == "gaze"


@pytest.mark.parametrize("tilt", ["tilt 70deg x3", "tilt 30deg x5"])
def test_more_tilts_than_gazes_measure_as_declared(tilt):
    """Compiled and measured, the tilts beside two gazes show the declared angle and
    velocity (and the file compiles: the roll never piles up)."""
    _, mismatches = _round_trip(f"approach\npause 1s x3\ngaze horizontal 20deg x2\n{tilt}\n")
    assert mismatches == []


def test_generated_descriptor_files_keep_the_roll_within_one_tilt():
    """Over generated descriptor-form files with tilts: the nth tilt in time turns
    +angle when n is even, -angle when odd."""
    seen = 0
    for case in langgen.random_cases(400, seed=3):
        if case.form != "descriptor":
            continue
        res = _lint(case.text)
        if res.timeline is None:
            continue
        tilts = [e for e in res.timeline.episodes if e.kind == "tilt"]
        for n, e in enumerate(tilts):
            turn = e.end.roll - e.start.roll
            assert (turn > 0) == (n % 2 == 0), case.text
            assert e.start.roll == pytest.approx(0.0 if n % 2 == 0 else abs(turn)), case.text
        seen += bool(tilts)
    assert seen > 20
