"""The compiler's registry of kinds: a plugin kind is timed and checked by its own
``Timing``, with no edit to the compiler, and one it cannot time is a K802."""

from __future__ import annotations

import pytest

from aou_dsl.compiler.kind_timing import BUILTIN_TIMINGS, missing, timing_of
from aou_dsl.compiler.pipeline import compile_behaviour
from aou_dsl.core.codes import C304, K802
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.linter import lint_source
from aou_dsl.lang.primitives import APPROACH, GAZE, PAUSE, SHIVER, TILT, Timing

from ..fake_plugins import LURCH, fresh_plugins, install  # noqa: F401

pytestmark = pytest.mark.usefixtures("fresh_plugins")

#: A sequence with the plugin's kind between two pauses.
FILE = """behaviour b
robot ur5
start 0.35m
standoff 15cm
sequence {{
  approach 10cm
  pause 1s
  lurch 2cm a={a}
  pause 1s
  approach 2cm
}}
"""
#: A descriptor of the lurch's peak acceleration, under a name no f-string would build.
PEAK = ('descriptors = (\n    Descriptor("lurch_peak", "m/s^2", NAME, "peak_acceleration", '
        'Aggregate.MAX, "a", rel_tol=0.03),\n')


def _compiled(tmp_path, monkeypatch, a, source=LURCH):
    install(tmp_path / "p", monkeypatch, entry="lurch", module="aou_fake_lurch_c",
            source=source, dist="aou-lurch")
    lint = lint_source(FILE.format(a=a), "b.aou")
    assert lint.ok, [d.message for d in lint.diagnostics]
    return compile_behaviour(lint.behaviour, timeline=lint.timeline)


def test_the_builtins_are_timed_by_their_timing():
    assert {k: t.timing for k, t in BUILTIN_TIMINGS.items()} == {
        APPROACH: Timing.OPTIMAL, PAUSE: Timing.HOLD, "retreat": Timing.OPTIMAL,
        GAZE: Timing.OPTIMAL, TILT: Timing.FIXED, SHIVER: Timing.OSCILLATION}
    assert timing_of(APPROACH).acceleration == REGISTRY["approach_acceleration"].name
    # a gaze's peak acceleration is no descriptor: C304 names it as it always has
    assert timing_of(GAZE).acceleration == "gaze_acceleration"
    assert timing_of(PAUSE).still and timing_of(SHIVER).still and not timing_of(TILT).still
    assert missing({APPROACH, PAUSE, GAZE, TILT, SHIVER, "retreat"}) is None


def test_a_plugin_kind_timed_like_a_retreat_compiles(tmp_path, monkeypatch):
    res = _compiled(tmp_path, monkeypatch, 0.3)
    assert res.ok, [d.message for d in res.diagnostics]
    kinds = [k for k, _, _ in res.trajectory.episodes]
    assert kinds == [APPROACH, PAUSE, "lurch", PAUSE, APPROACH]
    assert timing_of("lurch").timing is Timing.OPTIMAL and timing_of("lurch").translation


def test_a_plugin_kind_too_fast_for_the_arm_is_c304_naming_its_descriptor(
        tmp_path, monkeypatch):
    source = LURCH.replace("descriptors = (\n", PEAK)
    res = _compiled(tmp_path, monkeypatch, 80, source)
    (c304,) = [d for d in res.diagnostics if d.code == C304]
    assert c304.message.startswith("lurch reaches") and "m/s^2" in c304.message
    assert c304.refusal.descriptor == "lurch_peak"


@pytest.mark.parametrize("timing", ["OSCILLATION", "FIXED"])
def test_a_plugin_kind_the_compiler_cannot_time_is_k802(tmp_path, monkeypatch, timing):
    source = LURCH.replace("timing = Timing.OPTIMAL", f"timing = Timing.{timing}")
    res = _compiled(tmp_path, monkeypatch, 0.3, source)
    assert not res.ok and res.trajectory is None
    (d,) = res.diagnostics
    assert d.code == K802 and "`lurch`" in d.message and "aou-lurch 0.1" in d.message
    assert d.span.line == 8
