"""The C-V model: equations 1-2, nearest-state classification, and the inference."""

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aou_dsl.cv import (
    CANONICAL,
    CANONICAL_EFFORT,
    Composition,
    CVWeights,
    classify,
    composition_of,
    effort_to_cv,
    infer,
)
from aou_dsl.ir import State
from aou_dsl.lint import lint_file

from .conftest import BEHAVIOURS


@pytest.mark.parametrize("state", list(State))
def test_table_one_efforts_map_onto_their_points(state):
    """With the default weights of 1/2, Table I's Effort vectors give its C-V points."""
    p = effort_to_cv(CANONICAL_EFFORT[state])
    assert (p.C, p.V) == CANONICAL[state]
    assert p.state is state


def test_weights_are_configurable_and_positive():
    p = effort_to_cv((-1, 0, 1, 0), CVWeights(c1=1.0, c2=0.1, v1=0.25, v2=1.0))
    assert (p.C, p.V) == (1.0, 0.25)
    with pytest.raises(ValueError):
        CVWeights(c1=0)


def test_ties_break_in_table_order():
    """(0.5, -0.5) is equidistant from confident and hesitant: confident comes first."""
    assert classify(0.5, -0.5) is State.CONFIDENT
    assert classify(-0.5, 0.5) is State.HESITANT  # hesitant precedes fearful
    assert classify(0.0, 0.0) is State.HESITANT


@pytest.mark.parametrize("state", list(State))
def test_shipped_behaviours_infer_their_own_state(state):
    """Table II's four stimuli and the inactive file land in their declared states."""
    result = lint_file(str(BEHAVIOURS / f"{state}.aou"))
    assert result.behaviour.state is state
    assert result.cv.state is state
    assert not [d for d in result.diagnostics if d.code == "M201"]


def test_a_file_without_primitives_is_inactive():
    point, contrib = infer(Composition())
    assert point.state is State.INACTIVE and contrib == []


# --- monotonicity (issue 2, 4b) ------------------------------------------------------

compositions = st.builds(
    Composition,
    approach_acceleration=st.one_of(st.none(), st.floats(0.001, 5.0)),
    pause_count=st.integers(0, 20),
    pause_duration=st.floats(0.2, 10.0),
    retreat_count=st.integers(0, 10),
    retreat_distance=st.floats(0.001, 0.3),
    retreat_acceleration=st.floats(0.001, 5.0),
    gaze_swept=st.floats(0.0, 360.0),
    tilt_swept=st.floats(0.0, 360.0),
    shiver_amplitude=st.floats(0.1, 30.0),
    shiver_count=st.integers(0, 5),
)


def _with(c: Composition, **kw) -> Composition:
    return dataclasses.replace(c, **kw)


@settings(max_examples=300)
@given(compositions, st.integers(1, 5), st.floats(0.0, 0.2))
def test_more_or_longer_retreats_never_raise_commitment(c, extra, longer):
    base, _ = infer(c)
    more, _ = infer(_with(c, retreat_count=c.retreat_count + extra))
    farther, _ = infer(_with(c, retreat_distance=c.retreat_distance + longer))
    assert more.C <= base.C + 1e-12
    assert farther.C <= base.C + 1e-12


@settings(max_examples=300)
@given(compositions, st.floats(0.0, 5.0))
def test_higher_approach_acceleration_never_lowers_commitment(c, more):
    base, _ = infer(c)
    a = (c.approach_acceleration or 0.0) + more
    faster, _ = infer(_with(c, approach_acceleration=a or None))
    assert faster.C >= base.C - 1e-12


@settings(max_examples=300)
@given(compositions, st.integers(1, 5), st.floats(0.0, 90.0), st.floats(0.0, 90.0),
       st.integers(1, 3))
def test_adding_vigilance_primitives_never_lowers_vigilance(c, pauses, gaze, tilt, shivers):
    base, _ = infer(c)
    for kw in ({"pause_count": c.pause_count + pauses},
               {"gaze_swept": c.gaze_swept + gaze},
               {"tilt_swept": c.tilt_swept + tilt},
               {"shiver_count": c.shiver_count + shivers}):
        more, _ = infer(_with(c, **kw))
        assert more.V >= base.V - 1e-12, kw


def test_composition_of_a_sequence_adds_counts():
    from aou_dsl.lint import load

    b, _ = load("sequence {\n pause 1s x2\n retreat 2cm\n pause 1.5s\n retreat 3cm\n"
                " pause 1s\n gaze horizontal 20deg\n gaze horizontal -20deg\n}")
    comp = composition_of(b)
    assert comp.pause_count == 4 and comp.pause_duration == 1.5
    assert comp.retreat_count == 2 and comp.retreat_distance == pytest.approx(0.03)
    assert comp.gaze_swept == pytest.approx(40.0)


def test_docs_table_matches_the_code():
    """docs/cv-model.md lists each shipped behaviour's inferred point; it must be current."""
    import re

    from .conftest import ROOT

    text = (ROOT / "docs" / "cv-model.md").read_text()
    rows = re.findall(r"^\| (\w+) \| ([+-]\d\.\d\d) \| ([+-]\d\.\d\d) \| (\w+) \|$", text, re.M)
    assert len(rows) == 5
    for name, c, v, state in rows:
        r = lint_file(str(BEHAVIOURS / f"{name}.aou"))
        assert (f"{r.cv.C:+.2f}", f"{r.cv.V:+.2f}", r.cv.state.value) == (c, v, state)
