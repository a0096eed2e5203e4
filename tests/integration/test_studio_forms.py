"""The studio's sliders for every form of file users write, and Save's round trip.

Each form (the header-and-block descriptor form, the one-line form, a ``sequence``
block on many lines or on one, and both kinds of file ``aouc synth`` writes) gets a
slider for each descriptor it sets; a new value is written into the text token by token
(comments and layout kept), and the text compiles to a motion that measures with the new
value: the round trip declare -> compile -> measure is the oracle.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

from aou_dsl.api import compile as aou_compile
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.linter import lint_source
from aou_dsl.studio.edits import apply, settable
from aou_dsl.synth.synthesis import synthesize

ROOT = str(Path(__file__).resolve().parents[2])

ONE_LINE = "approach a=0.05; pause 1.67s x5; retreat 0.06m a=0.12 x3\n"
PEEK = """\
behaviour peek : curious
sequence {
  approach 0.08m a=0.09
  pause 1.25s
  gaze horizontal 20deg
  pause 1.25s
  gaze horizontal -20deg   # the other side
  pause 1.25s
  approach a=0.09          # no length: the rest of the way to the standoff
}
"""
SEQ_ONE_LINE = ("sequence { approach 0.08m a=0.09; pause 1.25s; retreat 0.05m a=0.1; "
                "pause 1.5s; approach a=0.09 }\n")


def _sliders(text: str) -> dict:
    lint = lint_source(text, "f.aou")
    assert lint.ok and lint.behaviour is not None, lint.diagnostics
    return settable(lint.behaviour, lint.timeline)


def _forms() -> dict[str, str]:
    with open(os.path.join(ROOT, "behaviours", "hesitant.aou"), encoding="utf-8") as f:
        hesitant = f.read()
    return {"header": hesitant, "one line": ONE_LINE, "sequence": PEEK,
            "sequence on one line": SEQ_ONE_LINE,
            "synth state": synthesize("fearful", intensity=0.7, verify=False),
            "synth blend": synthesize(C=-0.5, V=0.2, intensity=0.8, verify=False)}


#: What each form sets, as its statements say (the sequences: all but the counts).
SETS = {
    "header": {"approach_acceleration", "pause_count", "pause_duration", "retreat_count",
               "retreat_distance", "retreat_acceleration"},
    "one line": {"approach_acceleration", "pause_count", "pause_duration", "retreat_count",
                 "retreat_distance", "retreat_acceleration"},
    "sequence": {"approach_acceleration", "pause_duration", "horizontal_gaze"},
    "sequence on one line": {"approach_acceleration", "pause_duration", "retreat_distance",
                             "retreat_acceleration"},
    "synth state": {"approach_acceleration", "pause_count", "pause_duration", "retreat_count",
                    "retreat_distance", "retreat_acceleration", "shiver_amplitude"},
    "synth blend": {"approach_acceleration", "pause_count", "pause_duration", "retreat_count",
                    "retreat_distance", "retreat_acceleration"},
}


@pytest.mark.parametrize("form", list(SETS))
def test_every_form_gets_a_slider_for_each_descriptor_it_sets(form):
    assert set(_sliders(_forms()[form])) == SETS[form]


def test_the_one_line_form_changes_the_statement_that_sets_the_value():
    assert apply(ONE_LINE, {"pause_duration": 2.0}) == ONE_LINE.replace("1.67s", "2s")
    assert apply(ONE_LINE, {"retreat_count": 2}) == ONE_LINE.replace("x3", "x2")
    assert apply(ONE_LINE, {"retreat_distance": 0.08, "approach_acceleration": 0.07}) == \
        "approach a=0.07; pause 1.67s x5; retreat 0.08m a=0.12 x3\n"


def test_a_sequence_scales_its_statements_keeping_signs_proportions_and_comments():
    new = apply(PEEK, {"horizontal_gaze": 25.0, "approach_acceleration": 0.12})
    assert new == PEEK.replace("20deg", "25deg").replace("a=0.09", "a=0.12")
    assert _sliders(new)["horizontal_gaze"] == pytest.approx(25.0)
    # unequal pauses (one merged from `x2`): the median is the new value, the ratio stays
    text = "sequence { approach 0.08m; pause 1s x2; retreat 0.05m; pause 1s; approach }\n"
    assert _sliders(text)["pause_duration"] == pytest.approx(1.5)
    new = apply(text, {"pause_duration": 3.0})
    assert new == text.replace("1s", "2s")
    assert _sliders(new)["pause_duration"] == pytest.approx(3.0)


def test_a_sequence_value_left_to_its_default_is_added_to_each_statement():
    new = apply(SEQ_ONE_LINE.replace(" a=0.09", ""), {"approach_acceleration": 0.2})
    assert new.count("approach 0.08m a=0.2;") == 1 and new.count("approach a=0.2 }") == 1


def _skeleton(line: str) -> str:
    return re.sub(r"[-+]?[0-9][0-9.]*(e[-+]?[0-9]+)?", "N", line)


#: A new value for each form, and the descriptor it moves.
MOVES = {"header": ("pause_duration", 2.2), "one line": ("retreat_distance", 0.08),
         "sequence": ("horizontal_gaze", 26.0),
         "sequence on one line": ("pause_duration", 1.8),
         "synth state": ("pause_duration", 1.9), "synth blend": ("retreat_distance", 0.05)}


@pytest.mark.parametrize("form", list(MOVES))
def test_the_saved_text_keeps_its_layout_and_measures_the_new_value(form, tmp_path):
    text = _forms()[form]
    name, value = MOVES[form]
    new = apply(text, {name: value})
    old_lines, new_lines = text.splitlines(), new.splitlines()
    assert len(old_lines) == len(new_lines)
    for a, b in zip(old_lines, new_lines, strict=True):
        if a != b:  # only numbers change: every word, unit, comment and space stays
            assert a.lstrip().startswith(("approach", "pause", "retreat", "gaze", "sequence"))
            assert _skeleton(a) == _skeleton(b)
    path = tmp_path / "saved.aou"
    path.write_text(new)
    build = aou_compile(str(path), check=False)
    assert build.ok, build.diagnostics
    assert REGISTRY[name].matches(value, build.measured.descriptors[name])
    for other, was in _sliders(text).items():  # the others as the file had them
        if other != name and REGISTRY[other].is_count:
            assert build.measured.descriptors[other] == was


def _paused_and_saved(path, text: str, form: str, check):
    """``text`` opened in a studio: its sliders are those of ``form``; the pause set to
    2 s (``check(studio, motion)`` then) and saved. The motion shown."""
    pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")
    from aou_dsl.studio.app import Studio

    path.write_text(text)
    studio = Studio(str(path), port=0, watch=False).start()
    try:
        assert set(studio.sliders.values()) == SETS[form]
        m = studio.set_values({**studio.sliders.values(), "pause_duration": 2.0})
        assert m.ok
        check(studio, m)
        studio.save()
    finally:
        studio.close()
    return m


def test_save_of_a_one_line_file_writes_the_motion_shown(tmp_path):
    def shown(studio, m):
        assert studio.shown is m

    path = tmp_path / "one.aou"
    m = _paused_and_saved(path, ONE_LINE, "one line", shown)
    assert path.read_text() == ONE_LINE.replace("1.67s", "2s")
    build = aou_compile(str(path))
    assert build.ok
    assert np.array_equal(build.trajectory.t, m.trajectory.t)
    assert np.array_equal(build.trajectory.q, m.trajectory.q)
    assert sorted(os.listdir(tmp_path)) == ["one.aou"]


def test_a_blend_gets_an_intensity_slider_that_writes_it_again(tmp_path):
    pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")
    from aou_dsl.studio.app import Studio

    path = tmp_path / "blend.aou"
    path.write_text(synthesize(C=-0.5, V=0.2, intensity=0.5, verify=False))
    studio = Studio(str(path), port=0, watch=False).start()
    try:
        values = studio.sliders.values()
        assert values["intensity"] == 0.5 and "pause_duration" in values
        m = studio.set_values({**values, "intensity": 0.9})
        assert m.ok and studio.shown is m
        assert m.text == synthesize(C=-0.5, V=0.2, intensity=0.9, robot="panda",
                                    verify=False)
        assert studio.sliders.values()["intensity"] == 0.9
        studio.save()
        assert path.read_text() == m.text
    finally:
        studio.close()


def test_a_sequence_file_is_shaped_and_saved(tmp_path):
    def slider_moved(studio, m):
        assert studio.sliders.values()["pause_duration"] == pytest.approx(2.0)

    path = tmp_path / "peek.aou"
    m = _paused_and_saved(path, PEEK, "sequence", slider_moved)
    assert path.read_text() == PEEK.replace("1.25s", "2s")
    build = aou_compile(str(path))
    assert build.ok and np.array_equal(build.trajectory.q, m.trajectory.q)
    assert REGISTRY["pause_duration"].matches(2.0, build.measured.descriptors["pause_duration"])
