"""Stage 3: the layout follows the state's composition, deterministically, never closer
than the standoff, and realises the declared counts."""

import pytest

from aou_dsl.lang.declared import declared, written
from aou_dsl.lang.descriptors import derive
from aou_dsl.lang.layout import episode_values, layout
from aou_dsl.lang.linter import load
from tests.conftest import BEHAVIOURS


def _timeline(text: str):
    b, diags = load(text, "t.aou")
    assert b is not None, [d.message for d in diags]
    return b, layout(b)


@pytest.mark.parametrize("name", ["confident", "curious", "hesitant", "fearful", "inactive"])
def test_shipped_layouts_realise_their_descriptors(name):
    b, _ = _timeline((BEHAVIOURS / f"{name}.aou").read_text())
    tl = layout(b)
    want, got = written(b), derive(episode_values(tl.episodes))
    assert declared(b, tl) == want
    for key in ("pause_count", "retreat_count"):
        assert want[key] == got[key]
    assert layout(b) == tl  # deterministic


def test_confident_is_one_uninterrupted_approach_then_a_hold():
    _, tl = _timeline((BEHAVIOURS / "confident.aou").read_text())
    assert [e.kind for e in tl.episodes] == ["approach", "pause"]
    assert tl.episodes[0].start.d == pytest.approx(0.30)
    assert tl.episodes[0].end.d == pytest.approx(0.10)


def test_hesitant_advances_freezes_withdraws_freezes_repeats():
    _, tl = _timeline((BEHAVIOURS / "hesitant.aou").read_text())
    kinds = [e.kind for e in tl.episodes]
    assert kinds[0] == "approach" and kinds[-1] == "approach"
    for i, k in enumerate(kinds):  # every retreat is bracketed by pauses
        if k == "retreat":
            assert kinds[i - 1] == "pause" and kinds[i + 1] == "pause"
    assert kinds.count("approach") >= 2  # the advance is repeated


def test_curious_looks_from_both_sides():
    _, tl = _timeline((BEHAVIOURS / "curious.aou").read_text())
    bearings = [e.end.h for e in tl.episodes if e.kind == "gaze"]
    assert bearings[0] > 0 > bearings[1]
    assert abs(bearings[0]) == pytest.approx(abs(bearings[1]))


def test_inactive_makes_no_progress():
    _, tl = _timeline((BEHAVIOURS / "inactive.aou").read_text())
    assert all(e.kind != "approach" for e in tl.episodes)
    assert all(e.end.d == pytest.approx(0.30) for e in tl.episodes)


@pytest.mark.parametrize("text", [
    "approach a=0.05; pause 1s x7; retreat 0.08m x4",
    "behaviour f : fearful; approach; pause 1s x3; retreat 0.2m a=2 x2; shiver 4deg",
    "approach; pause 1s x4; gaze horizontal 30deg x2; gaze vertical 10deg; tilt 10deg x3",
    "start 0.2m; standoff 0.15m; approach; pause 1s x4; retreat 0.1m x3",
])
def test_never_inside_the_standoff_and_ends_there(text):
    b, tl = _timeline(text)
    standoff = b.settings.standoff
    assert all(e.end.d >= standoff - 1e-12 and e.start.d >= standoff - 1e-12
               for e in tl.episodes)
    last_move = [e for e in tl.episodes if e.kind in ("approach", "retreat")][-1]
    assert last_move.end.d == pytest.approx(standoff)


def test_no_two_pauses_touch_in_the_descriptor_form():
    _, tl = _timeline("approach; pause 1s x6; retreat 3cm x2; gaze horizontal 10deg")
    kinds = [e.kind for e in tl.episodes]
    assert all(not (a == b == "pause") for a, b in zip(kinds, kinds[1:], strict=False))


def test_statement_order_does_not_matter_in_the_descriptor_form():
    _, a = _timeline("approach a=0.05; pause 1.67s x5; retreat 0.06m a=0.12 x3")
    _, b = _timeline("retreat 0.06m a=0.12 x3\npause 1.67s x5\napproach a=0.05")
    assert [(e.kind, e.start, e.end) for e in a.episodes] == \
        [(e.kind, e.start, e.end) for e in b.episodes]


def test_sequence_is_taken_verbatim():
    _, tl = _timeline("sequence {\n approach 0.08m\n pause 1s x2\n gaze horizontal -20deg\n"
                      " approach\n}")
    assert [e.kind for e in tl.episodes] == ["approach", "pause", "pause", "gaze", "approach"]
    assert tl.episodes[3].end.h == pytest.approx(-0.349, abs=1e-3)
