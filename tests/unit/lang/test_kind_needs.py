"""The kinds' needs: what a kind needs around it to count is the kind's property, read by
the descriptors' qualifying, the layout and V121, so a new kind (a plugin's) is laid out
by its own needs with no edit of the layout."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import pytest

from aou_dsl import api
from aou_dsl.lang import kind_needs, primitives, stops
from aou_dsl.lang import layout as layout_module
from aou_dsl.lang.descriptors import EpisodeValues, qualify
from aou_dsl.lang.ir import Node
from aou_dsl.lang.kind_needs import episode_values, shows_all, why_not
from aou_dsl.lang.layout import layout
from aou_dsl.lang.primitives import APPROACH, GAZE, KINDS, PAUSE, RETREAT, TILT
from aou_dsl.lang.primitives.kind import Kind, Needs, move
from aou_dsl.lang.timeline import Pose

WIND = "windup"


@dataclass(frozen=True, kw_only=True, slots=True)
class Windup(Node):
    kind: Literal["windup"] = "windup"
    length: float = 0.01


class WindupKind(Kind):
    """A test kind: a small move away from the goal that counts only directly before an
    approach (a wind-up, as an animator draws before a move)."""

    name = WIND
    node = Windup
    usage = "windup LENGTH [xN]"
    translation = True
    evidence = {}
    needs = Needs(followed_by=APPROACH)

    def read(self, r):  # pragma: no cover - built by hand here
        return None

    def episode(self, node, pose, arg=None):
        return move(WIND, node.span, pose, Pose(pose.d + node.length, pose.h, pose.v,
                                                pose.roll), 0.1, 0.25)

    def values(self, node):
        return {"distance": node.length}

    def episode_values(self, ep):
        return {"distance": ep.path_length}

    def format(self, node):  # pragma: no cover
        return f"windup {node.length}m x{node.count}"


@pytest.fixture
def windup(monkeypatch):
    """The kinds with the test kind added, as the modules of the layout and the
    descriptors read them (whatever holds the kinds, a dict or a live view of plugins)."""
    kinds = {**KINDS, WIND: WindupKind()}
    for module in (primitives, stops, kind_needs, layout_module):
        monkeypatch.setattr(module, "KINDS", kinds)


def test_the_built_in_kinds_say_their_needs():
    assert KINDS[RETREAT].needs == Needs(preceded_by=PAUSE, followed_by=PAUSE)
    assert KINDS[GAZE].needs == Needs(followed_by=PAUSE)
    assert KINDS[PAUSE].needs.apart
    assert KINDS[TILT].needs == Needs() and KINDS[APPROACH].needs == Needs()
    assert KINDS[RETREAT].needs.words(RETREAT, PAUSE) == (
        "a retreat counts only between two pauses, one before and one after it")
    assert KINDS[GAZE].needs.words(GAZE, PAUSE) == "a gaze counts only when a pause ends it"


def _marks(kinds):
    return [e.counts for e in qualify(EpisodeValues(k) for k in kinds)]


def test_qualify_reads_the_needs_of_a_new_kind(windup):
    assert _marks([WIND, APPROACH, PAUSE, WIND, PAUSE, APPROACH, WIND]) == [
        True, True, True, False, True, True, False]
    assert _marks([PAUSE, RETREAT, PAUSE, RETREAT, APPROACH]) == [
        True, True, True, False, True]


def _behaviour(text, *extra):
    b = api.lint(source=text, path="t.aou").behaviour
    assert b is not None
    return b.replace(primitives=(*b.primitives, *extra))


@pytest.mark.parametrize("state", ["confident", "curious", "hesitant", "fearful", "inactive"])
def test_a_new_kind_is_laid_out_by_its_needs(windup, state):
    b = _behaviour(f"behaviour w : {state}\nstart 0.4m\nstandoff 10cm\napproach\n"
                   "pause 1s x3\nretreat 2cm\ngaze horizontal 10deg\n",
                   Windup(span=_span(), count=2))
    eps = layout(b).episodes
    kinds = [e.kind for e in eps]
    at = [i for i, k in enumerate(kinds) if k == WIND]
    assert len(at) == 2, kinds
    assert all(kinds[i + 1] == APPROACH for i in at), kinds  # directly, no pause between
    assert shows_all(b, eps)
    assert all(e.counts for e in qualify(episode_values(eps)) if e.kind in (WIND, RETREAT))


def test_a_new_kind_whose_neighbour_the_file_lacks_is_named(windup):
    """The need no layout can meet is said once; it bars no gap from the pauses, which
    still show (a second V121 for them would blame the pauses for the kind's need)."""
    b = _behaviour("pause 1s x3\ntilt 10deg x2\n", Windup(span=_span(), count=2))
    b = b.replace(primitives=tuple(p.replace(count=4) if p.kind == PAUSE else p
                                   for p in b.primitives))  # 4 motions, room for 5
    assert why_not(b) == ("a windup counts only directly before an approach, nothing "
                          "between, and this file has no approach")
    values = qualify(episode_values(layout(b).episodes))
    assert sum(1 for e in values if e.kind == PAUSE) == 4


def _span():
    return api.lint(source="pause 1s\n").behaviour.primitives[0].span


def test_the_docs_give_the_layouts_orders_and_bound():
    from pathlib import Path

    from aou_dsl.lang.stops import MAX_WAYS, STOP_ORDER

    text = (Path(__file__).resolve().parents[3] / "docs" / "compiler.md").read_text()
    for state, order in STOP_ORDER.items():
        assert f"| {state.value} | {', '.join(order)} |" in text
    assert f"at most {MAX_WAYS} arrangements" in text
