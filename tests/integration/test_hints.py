"""What lint and compile say about values that do not work, and whether the value they
suggest does: applied to the file, the suggestion compiles (and passes the checks); one
step above it (at the precision it is given) does not. Also the arguments the language
does not take (an approach's `xN`), and a shiver's frequency and duration bounds."""

import math
import re

import numpy as np
import pytest

from aou_dsl.compiler.oscillation import shiver_offset, shiver_ratios
from aou_dsl.driver.builder import build_source
from aou_dsl.fit.rounding import significant, times
from aou_dsl.fit.search import largest_fitting
from aou_dsl.lang.linter import lint_source
from aou_dsl.robot.load import load_arm


def _lint(text: str):
    return lint_source(text, "t.aou")


def _errors(res) -> list:
    return [d for d in res.diagnostics if d.severity == "error"]


def _one(res, code: str):
    found = [d for d in res.diagnostics if d.code == code]
    assert len(found) == 1, [(d.code, d.message) for d in res.diagnostics]
    return found[0]


def _at(text: str, d) -> str:
    """The source text a diagnostic's span covers (one line)."""
    line = text.split("\n")[d.span.line - 1]
    return line[d.span.col - 1:d.span.end_col - 1]


def _apply(text: str, d) -> str:
    """The file with the diagnostic's hint `write `k=VALUE`` applied to its statement."""
    from aou_dsl.fit.text_edits import apply_edit

    m = re.fullmatch(r"write `((\w+)=([0-9.]+)([A-Za-z/]+)( for [0-9.]+s)?)`", d.hint or "")
    assert m, d.hint
    fixed = apply_edit(text, d.span, m.group(1))
    assert fixed != text
    return fixed


def _next_up(x: float) -> float:
    """The next value of two significant digits above ``x``."""
    unit = 10.0 ** (math.floor(math.log10(x)) - 1)
    return round(x + unit, 12)


# --- an approach's repeat count -------------------------------------------------------


@pytest.mark.parametrize("count", ["x3", "x1"])
def test_descriptor_approach_takes_no_repeat_count(count):
    """The descriptor form's approach runs once, from start to standoff: a count is an
    error at the count, not ignored."""
    text = f"approach a=0.1 {count}\npause 1s\n"
    d = _one(_lint(text), "V113")
    assert _at(text, d) == count
    assert "sequence" in (d.hint or "")
    assert _lint("approach a=0.1\npause 1s\n").ok


def test_sequence_approach_repeats_with_a_length():
    """In a sequence `xN` repeats a statement in place: three approaches of 5 cm."""
    res = _lint("sequence {\n  approach 0.05m x3\n  pause 1s\n}\n")
    assert res.ok, [d.message for d in res.diagnostics]
    moves = [e for e in res.timeline.episodes if e.kind == "approach"]
    assert len(moves) == 3
    start = res.behaviour.settings.start
    assert [e.end.d for e in moves] == pytest.approx([start - 0.05, start - 0.10,
                                                      start - 0.15])


def test_sequence_approach_without_length_cannot_repeat():
    """Without a length the approach runs the rest of the way: a second one has nothing
    left to approach, so a count above 1 is an error (x0 and x1 mean absent and once)."""
    text = "sequence {\n  approach 0.05m\n  pause 1s\n  approach x2\n}\n"
    d = _one(_lint(text), "V113")
    assert _at(text, d) == "x2"
    for ok in ("x1", "x0"):
        assert _lint(f"sequence {{\n  approach 0.05m\n  pause 1s\n  approach {ok}\n}}\n").ok


# --- the suggestions' arithmetic ----------------------------------------------------------


def test_significant_rounds_down_and_keeps_exact_values():
    assert significant(2.2734, 2) == 2.2
    assert significant(2.2, 2) == 2.2  # 2.2 is stored as 2.2000000000000002 or 2.19999...
    assert significant(84.999, 2) == 84
    assert significant(0.0123, 2) == 0.012
    assert significant(100.0, 2) == 100


def test_largest_fitting_searches_both_ways():
    """From any estimate, the largest two-digit value under the refused one that fits."""
    def fits(x):
        return x <= 2.2734

    for estimate in (0.5, 2.27, 2.4, 6.0):
        assert largest_fitting(estimate, fits, below=7.0) == 2.2
    assert largest_fitting(40.0, lambda x: x <= 100.0, below=50.0) == 49
    assert largest_fitting(1.0, lambda x: False, below=2.0) is None


def test_a_ratio_is_never_shown_below_what_it_is():
    assert times(1.0004) == "1.01"
    assert times(2.5) == "2.50"
    assert times(15.51) == "15.6"


# --- shivers: the limits, and the frequency that fits ------------------------------------


def test_shiver_peaks_follow_the_motion_itself():
    """The check's peaks (from the unit shiver, scaled) equal the peaks of the offset it
    compiles, sampled densely: velocity and acceleration by the offset's derivatives,
    jerk by differences of the acceleration."""
    arm = load_arm("panda")
    j = arm.joint_names.index(arm.spec.shiver_joint)
    amp, f, duration = math.radians(7.0), 2.4, 5 / 2.4
    tau = np.linspace(0.0, duration, 400_001)
    _, xd, xdd, _ = shiver_offset(tau, amp, f, duration)
    jerk = np.abs(np.diff(xdd)) / (tau[1] - tau[0])
    from aou_dsl.compiler.peak_limits import JERK_SCALE

    expected = (np.abs(xd).max() / arm.plan_vmax[j], np.abs(xdd).max() / arm.plan_amax[j],
                jerk.max() / (arm.jmax[j] * JERK_SCALE))
    assert shiver_ratios(arm, amp, f, duration) == pytest.approx(expected, rel=1e-4)


#: Amplitudes the arm follows at 2.5 Hz or faster (a slower frequency is not offered:
#: the shiver would read as slow rolls).
SHIVERS = [
    ("", "8deg", "7Hz"),
    ("", "8deg", "2.9Hz"),
    ("robot ur5\n", "2deg", "7Hz"),
    ("robot xarm7\n", "6deg", "8Hz"),
]


@pytest.mark.parametrize(("robot", "amp", "f"), SHIVERS)
def test_c308_suggests_the_highest_frequency_that_compiles(robot, amp, f):
    text = f"{robot}shiver {amp} f={f}\n"
    d = _one(build_source(text, "t.aou", check=False), "C308")
    arm = load_arm(robot.split()[1] if robot else "panda")
    m = re.search(r"needs [0-9.]+x (\S+)'s (velocity|acceleration|jerk) limit", d.message)
    assert m and m.group(1) == arm.spec.shiver_joint == d.fields["joint"]
    assert m.group(2) == d.fields["limit"]
    fixed = _apply(text, d)
    res = build_source(fixed, "t.aou")
    assert res.ok, (fixed, [(x.code, x.message) for x in res.diagnostics])
    f_ok = d.fields["max_frequency"]
    assert f"{f_ok:g} Hz" in d.message
    above = fixed.replace(f"f={f_ok:g}Hz", f"f={_next_up(f_ok):g}Hz")
    assert "C308" in {x.code for x in build_source(above, "t.aou", check=False).diagnostics}


def test_c308_offers_a_smaller_amplitude_when_no_frequency_fits():
    """60 deg at 2.5 Hz would need a shiver slower than the language allows: the
    amplitude that fits at 2.5 Hz is given instead, and it compiles."""
    d = _one(build_source("shiver 60deg f=2.5Hz\n", "t.aou", check=False), "C308")
    assert "Hz fits" not in d.message
    # the hint is the amplitude that fits at 2.5 Hz (the rule of --fit, under that bound)
    hinted = re.fullmatch(r"write `shiver ([0-9.]+)deg f=2.5Hz` at line 1", d.hint)
    assert hinted, d.hint
    assert build_source(f"shiver {hinted.group(1)}deg f=2.5Hz\n", "t.aou").ok
    m = re.search(r"at most ([0-9.]+) deg at 2.5 Hz", d.message)
    assert m, d.message
    res = build_source(f"shiver {m.group(1)}deg f=2.5Hz\n", "t.aou")
    assert res.ok, [(x.code, x.message) for x in res.diagnostics]


# --- tilts: which limit, and the velocity that fits ----------------------------------------


def test_c309_names_the_limit_and_its_suggestion_compiles():
    text = "tilt 90deg v=180deg/s\n"
    d = _one(build_source(text, "t.aou", check=False), "C309")
    arm = load_arm("panda")
    m = re.search(r"needs [0-9.]+x (\S+)'s (velocity|acceleration|jerk) limit", d.message)
    assert m and m.group(1) in arm.joint_names and m.group(1) == d.fields["joint"]
    fixed = _apply(text, d)
    res = build_source(fixed, "t.aou")
    assert res.ok, (fixed, [(x.code, x.message) for x in res.diagnostics])
    v_ok = d.fields["max_velocity"]
    above = fixed.replace(f"v={v_ok:g}deg/s", f"v={_next_up(v_ok):g}deg/s")
    assert "C309" in {x.code for x in build_source(above, "t.aou", check=False).diagnostics}


def test_c309_factor_grows_with_the_velocity():
    """The same tilt at a higher velocity lasts less: its peak joint speed grows in
    proportion (the law is the same, squeezed in time), and so does the factor; the
    velocity that fits stays the same."""
    found = {}
    for v in (120, 180):
        d = _one(build_source(f"tilt 90deg v={v}deg/s\n", "t.aou", check=False), "C309")
        assert d.fields["limit"] == "velocity", d.message
        factor = float(re.search(r"needs ([0-9.]+)x", d.message).group(1))
        found[v] = (factor, d.fields["max_velocity"])
    assert found[180][0] / found[120][0] == pytest.approx(180 / 120, rel=0.02)
    assert found[180][1] == found[120][1]


def test_c309_suggestion_does_not_depend_on_how_far_over():
    """On an arm whose null space turns with the roll (xarm7), the jerk and acceleration
    bind; the velocity that fits is one value, whatever the declared one, and it compiles
    and passes the checks (the controller's jerk check included)."""
    base = "robot xarm7\napproach\npause 1s x2\ntilt 90deg v={}deg/s\n"
    suggested = set()
    for v in (45, 85, 180):
        d = _one(build_source(base.format(v), "t.aou", check=False), "C309")
        assert d.fields["limit"] in ("velocity", "acceleration", "jerk")
        suggested.add(d.fields["max_velocity"])
    assert len(suggested) == 1
    res = build_source(base.format(suggested.pop()), "t.aou")
    assert res.ok, [(x.code, x.message) for x in res.diagnostics]


def test_c309_suggestion_fits_every_tilt_of_the_statement():
    """`v=` times all the tilts a statement makes; the suggestion holds for all three,
    though the first one alone would take a faster one."""
    text = ("behaviour c : curious\napproach\npause 1s x3\ngaze horizontal 20deg\n"
            "gaze vertical 15deg\ntilt 70deg v=300deg/s x3\n")
    d = _one(build_source(text, "t.aou", check=False), "C309")
    assert "all 3 tilts" in d.message
    res = build_source(_apply(text, d), "t.aou")
    assert res.ok, [(x.code, x.message) for x in res.diagnostics]


# --- a shiver's frequency and duration ---------------------------------------------------------


def test_a_shiver_is_at_least_one_hertz():
    text = "shiver 5deg f=0.01Hz for 1s\n"
    d = _one(_lint(text), "V105")
    assert _at(text, d) == "0.01Hz"
    assert _lint("shiver 5deg f=1Hz for 3s\n").ok


def test_the_slowest_shiver_measures_as_declared():
    """At the lowest frequency and the smallest visible amplitude, the compiled shiver is
    still measured as one shiver of its amplitude, between the pauses the file declares
    (a slower one reads as a pause inside it)."""
    text = "behaviour s : fearful\napproach\npause 1s x3\nretreat 0.05m\nshiver 1deg f=1Hz\n"
    res = build_source(text, "t.aou", check=False)
    assert res.ok, [(x.code, x.message) for x in res.diagnostics]
    measured = res.measured.descriptors
    assert measured["shiver_amplitude"] == pytest.approx(1.0, abs=0.5)
    assert measured["pause_count"] == 3


def _shiver_episode(text: str):
    res = _lint(text)
    assert res.ok, [d.message for d in res.diagnostics]
    return next(e for e in res.timeline.episodes if e.kind == "shiver")


def test_a_shiver_lasts_at_least_three_cycles():
    """It fades in over its first cycle and out over its last: at 1 Hz, 3 s."""
    assert _shiver_episode("shiver 5deg f=1Hz for 1s\n").duration == pytest.approx(3.0)
    assert _shiver_episode("shiver 5deg f=2.5Hz for 1.25s\n").duration == pytest.approx(1.2)


def test_a_lengthened_shiver_is_a_warning_at_its_for():
    text = "shiver 5deg f=1Hz for 1s\n"
    d = _one(_lint(text), "V126")
    assert d.severity == "warning" and _at(text, d) == "for 1s"
    assert "3 cycles" in d.message and "3.00 s" in d.message
    written = re.search(r"`(for [0-9.]+s)`", d.hint).group(1)
    fixed = text.replace("for 1s", written)
    assert not [x for x in _lint(fixed).diagnostics if x.code == "V126"]
    assert _shiver_episode(fixed).duration == pytest.approx(3.0)
    # Rounding to whole cycles is no warning; nor is the default duration.
    for quiet in ("shiver 5deg f=2.5Hz for 1.25s\n", "shiver 5deg f=1Hz\n"):
        assert not [x for x in _lint(quiet).diagnostics if x.code == "V126"]
