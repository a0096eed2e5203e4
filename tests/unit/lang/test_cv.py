"""The C-V model: equations 1-2, nearest-state classification, and the inference."""

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aou_dsl.lang.cv import (
    CANONICAL,
    CANONICAL_EFFORT,
    Composition,
    CVWeights,
    classify,
    composition,
    effort_to_cv,
    infer,
)
from aou_dsl.lang.ir import State
from aou_dsl.lang.linter import lint_file
from tests.conftest import BEHAVIOURS


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


# --- monotonicity ---------------------------------------------------------------------

compositions = st.builds(
    Composition,
    drive=st.floats(0.0, 5.0),
    extent=st.floats(0.0, 3.0),
    vigour=st.floats(0.0, 5.0),
    stillness=st.floats(0.0, 100.0),
    exploration=st.floats(0.0, 720.0),
    tremor=st.floats(0.0, 150.0),
)


def _with(c: Composition, **kw) -> Composition:
    return dataclasses.replace(c, **kw)


@settings(max_examples=300)
@given(compositions, st.floats(0.0, 1.0), st.floats(0.0, 5.0))
def test_more_or_longer_or_faster_retreats_never_raise_commitment(c, farther, faster):
    base, _ = infer(c)
    more, _ = infer(_with(c, extent=c.extent + farther))
    vigorous, _ = infer(_with(c, vigour=c.vigour + faster))
    assert more.C <= base.C + 1e-12
    assert vigorous.C <= base.C + 1e-12


@settings(max_examples=300)
@given(compositions, st.floats(0.0, 5.0))
def test_higher_approach_acceleration_never_lowers_commitment(c, more):
    base, _ = infer(c)
    faster, _ = infer(_with(c, drive=c.drive + more))
    assert faster.C >= base.C - 1e-12


@settings(max_examples=300)
@given(compositions, st.floats(0.0, 20.0), st.floats(0.0, 90.0), st.floats(0.0, 30.0))
def test_adding_vigilance_primitives_never_lowers_vigilance(c, pauses, explore, tremor):
    base, _ = infer(c)
    for kw in ({"stillness": c.stillness + pauses},
               {"exploration": c.exploration + explore},
               {"tremor": c.tremor + tremor}):
        more, _ = infer(_with(c, **kw))
        assert more.V >= base.V - 1e-12, kw


def test_composition_of_a_sequence_reads_what_the_episodes_do():
    """Pause time and retreat distance add up; gazes count their angle from the line of
    sight; a negative approach moves away from the goal and counts as a retreat."""
    from aou_dsl.lang.layout import episode_values
    from aou_dsl.lang.linter import load_validated

    v = load_validated("sequence {\n pause 1s x2\n retreat 2cm\n pause 1.5s\n retreat 3cm\n"
                       " pause 1s\n gaze horizontal 20deg\n gaze horizontal -20deg\n"
                       " approach -1cm\n}")
    comp = composition(episode_values(v.timeline.episodes))
    assert comp.stillness == pytest.approx(4.5)
    assert comp.extent == pytest.approx(0.06)
    assert comp.exploration == pytest.approx(40.0)


def test_a_negative_approach_is_not_confident():
    """`sequence { approach -0.8m }` moves away from the goal: it cannot read as
    confident (the model classifies motion by what it does)."""
    from aou_dsl.lang.linter import lint_source

    r = lint_source("start 0.15m\nsequence { approach -0.5m }")
    assert r.ok and r.cv is not None
    assert r.cv.state is not State.CONFIDENT and r.cv.C < 0


def test_docs_table_matches_the_code():
    """docs/cv-model.md lists each shipped behaviour's inferred point; it must be current."""
    import re

    from tests.conftest import ROOT

    text = (ROOT / "docs" / "cv-model.md").read_text()
    rows = re.findall(r"^\| (\w+) \| ([+-]\d\.\d\d) \| ([+-]\d\.\d\d) \| (\w+) \|$", text, re.M)
    assert len(rows) == 5
    for name, c, v, state in rows:
        r = lint_file(str(BEHAVIOURS / f"{name}.aou"))
        assert (f"{r.cv.C:+.2f}", f"{r.cv.V:+.2f}", r.cv.state.value) == (c, v, state)
