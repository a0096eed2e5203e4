"""Files written by people, each with the values a reader of the file expects.

Every case below is a valid file that once compiled wrong, measured wrong or was refused
without reason. The expected values are read off the file by the language's definitions
(a gaze's angle from the start's line of sight in its plane, a tilt's unwrapped roll, a
pause's hold), never taken from what the compiler printed. ``None`` means the descriptor
is absent (null); a key that is not listed is not asserted.
"""

from __future__ import annotations

import math

import pytest

from aou_dsl.driver.builder import build_source
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.linter import lint_source

CURIOUS = """behaviour curious : curious
approach a=0.3
pause 1.25s x3
gaze horizontal 15deg x2
gaze vertical 10deg x2
tilt 15deg v=30deg/s
"""

CASES: dict[str, tuple[str, dict[str, float | None]]] = {
    "gaze-with-tilt": (
        "approach a=0.1; pause 1s x2; gaze horizontal 20deg; tilt 10deg",
        {"horizontal_gaze": 20, "tilt_angle": 10, "pause_count": 2, "pause_duration": 1,
         "approach_acceleration": 0.1}),
    "curious-plus-tilts": (
        CURIOUS.replace("tilt 15deg v=30deg/s", "tilt 15deg x2"),
        {"horizontal_gaze": 15, "vertical_gaze": 10, "tilt_angle": 15, "pause_count": 3}),
    "planes-compose": (
        "sequence {\n approach\n gaze vertical 20deg\n pause 1s\n gaze horizontal 30deg\n"
        " pause 1s\n}",
        {"horizontal_gaze": 30, "vertical_gaze": 20, "pause_count": 2}),
    "speed-cap-short-ramp": (
        "approach a=0.1 v=0.02\npause 1s",
        {"approach_acceleration": 0.1}),
    "slow-alternating-tilts": (
        "approach a=0.2; pause 1s x2; tilt 10deg v=5deg/s x3",
        {"tilt_angle": 10, "tilt_velocity": 5, "shiver_amplitude": None, "pause_count": 2}),
    "shiver-between-tilts": (
        "sequence {\n approach\n pause 1s\n tilt 20deg\n shiver 4deg for 1.5s\n"
        " tilt -20deg\n pause 1s\n}",
        {"shiver_amplitude": 4, "tilt_angle": 20, "pause_count": 2}),
    "big-tilt-unwraps": (
        "sequence {\n approach\n pause 1s\n tilt 200deg v=60deg/s\n pause 1s\n}",
        {"tilt_angle": 200, "tilt_velocity": 60, "pause_count": 2}),
    "short-fast-tilt": (
        "approach a=0.2; pause 1s x2; tilt 2deg v=20deg/s",
        {"tilt_angle": 2, "tilt_velocity": 20}),
    "slow-tilt-no-extra-pauses": (
        "approach a=0.2; pause 1s x2; tilt 30deg v=2deg/s",
        {"tilt_angle": 30, "tilt_velocity": 2, "pause_count": 2}),
    "gaze-after-big-tilt": (
        "sequence {\n approach\n pause 1s\n tilt 50deg\n gaze horizontal 20deg\n pause 1s\n"
        " gaze horizontal -20deg\n pause 1s\n}",
        {"horizontal_gaze": 20, "tilt_angle": 50, "pause_count": 3}),
    "look-and-return": (
        "sequence {\n approach\n pause 1s\n gaze horizontal 20deg\n pause 1s\n"
        " gaze horizontal 0deg\n pause 1s\n}",
        {"horizontal_gaze": 20, "pause_count": 3}),
    "touching-pauses-are-one": (
        "sequence {\n approach\n pause 1s x2\n retreat 0.05m\n pause 1s\n}",
        {"pause_count": 2, "pause_duration": 1.5, "retreat_count": 1,
         "retreat_distance": 0.05}),
    "bare-angular-speed-is-deg-per-s": (
        "approach a=0.2; pause 1s x2; tilt 10deg v=20",
        {"tilt_angle": 10, "tilt_velocity": 20}),
    "no-approach": (
        "pause 1s x3; gaze horizontal 15deg x2",
        {"pause_count": 3, "horizontal_gaze": 15, "approach_acceleration": None}),
    "retreats-share-pauses-with-a-gaze": (
        "behaviour b : curious\npause 0.5s x3\ngaze horizontal 10deg x2\napproach\n"
        "retreat 0.04m a=0.1 x2",
        {"pause_count": 3, "retreat_count": 2, "horizontal_gaze": 10}),
    "short-standoff-no-branch-flip": (
        "start 0.25m; standoff 0.0625m; approach a=0.25; pause 1s x4; retreat 0.0625m a=1; "
        "gaze horizontal 19deg; gaze vertical 11deg; tilt 5deg v=8deg/s; "
        "shiver 2deg f=2Hz for 1.5s",
        {"approach_acceleration": 0.25, "pause_count": 4, "retreat_count": 1,
         "horizontal_gaze": 19, "vertical_gaze": 11, "tilt_angle": 5, "shiver_amplitude": 2}),
}


def _close(name: str, expected: float, found: float) -> bool:
    d = REGISTRY[name]
    return abs(found - expected) <= max(d.abs_tol, d.rel_tol * abs(expected))


#: Cases whose fix is not in yet: strict, so the fix must remove them from here.
PENDING: dict[str, str] = {}


@pytest.mark.parametrize("case", [
    pytest.param(c, marks=pytest.mark.xfail(reason=PENDING[c], strict=True)) if c in PENDING
    else c for c in sorted(CASES)])
def test_written_files_measure_as_read(case):
    text, expected = CASES[case]
    res = build_source(text, f"{case}.aou")
    assert res.ok, [str(d) for d in res.diagnostics]
    measured = res.measured.descriptors
    wrong = {}
    for name, want in expected.items():
        got = measured[name]
        if want is None or got is None:
            if want is not got:
                wrong[name] = (want, got)
        elif not _close(name, float(want), float(got)):
            wrong[name] = (want, got)
    assert not wrong, f"expected vs measured: {wrong}"


@pytest.mark.parametrize("text, code", [
    ("", "V124"),
    ("robot panda", "V124"),
    ("sequence {}", "V124"),
    ("approach a=0.1; pause 1s x4; retreat 0.3m x3", "V119"),
    ("start 2m\napproach", "V119"),
    ("standoff 0.12m\napproach a=0.1\npause 1s x2\ngaze horizontal 1deg", "V123"),
])
def test_impossible_files_are_refused_by_lint_with_a_code(text, code):
    diags = lint_source(text, "x.aou").diagnostics
    assert code in {d.code for d in diags if d.severity == "error"}, [str(d) for d in diags]


def test_a_gaze_too_small_to_see_says_millimetres():
    (d,) = [d for d in lint_source("standoff 0.12m\napproach a=0.1\npause 1s x2\n"
                                   "gaze horizontal 1deg", "x.aou").diagnostics
            if d.code == "V123"]
    assert " mm" in d.message and "5 mm" in d.message


def test_touching_pauses_in_a_sequence_are_a_note():
    diags = lint_source("sequence {\n approach\n pause 1s\n pause 1s\n}", "x.aou").diagnostics
    (note,) = [d for d in diags if d.code == "V125"]
    assert note.severity == "note" and note.span.line == 4


def test_a_negative_approach_is_not_confident():
    res = lint_source("sequence {\n approach -0.3m\n pause 1s\n}", "x.aou")
    assert res.cv is not None and res.cv.state.value != "confident"


def test_low_output_rate_keeps_checks_dense_and_ends_at_rest():
    res = build_source("approach a=0.3\npause 1s x2\nretreat 0.05m a=0.5", "x.aou", rate=1.0)
    assert res.ok, [str(d) for d in res.diagnostics]
    tr = res.trajectory
    assert math.isclose(tr.t[-1], res.compiled.trajectory.t[-1])
    assert abs(tr.qd[-1]).max() < 1e-9
