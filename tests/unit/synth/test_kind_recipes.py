"""The synthesis recipe registry: every built-in kind, a plugin's ``synth`` part merged,
and a plugin kind without one left out of synthesis (not a crash)."""

from __future__ import annotations

from types import SimpleNamespace

from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.ir import State
from aou_dsl.lang.primitives import KINDS
from aou_dsl.synth import kind_recipes as reg
from aou_dsl.synth.recipe import slot_of
from aou_dsl.synth.synthesis import recipe
from tests.unit import kind_plugin_fake as fake

BUILTIN = [k for k in KINDS if k != fake.NAME]
CANONICAL = (State.CONFIDENT, State.CURIOUS, State.HESITANT, State.FEARFUL)


def test_every_builtin_kind_and_descriptor_has_its_recipe():
    kinds = reg.kind_recipes()
    assert list(kinds)[:len(BUILTIN)] == BUILTIN  # a file's statements in the kinds' order
    slots = reg.slots()
    assert len(set(slots)) == len(slots)
    for d in REGISTRY.values():
        assert slot_of(d) in slots, d.name
        # the study's directions are the ones synthesis moves: each has its span
        for state in CANONICAL:
            if state in d.stronger:
                assert reg.span_of(state, d.kind, d.key) is not None, (state, d.name)


def test_the_pauses_a_file_needs_follow_the_kinds_needs():
    # a retreat starts and ends at a pause (shared between neighbours); a look ends at one
    def counts(**n: int):
        return lambda kind, plane=None: n.get(f"{kind}_{plane}" if plane else kind, 0)

    assert reg.pauses_needed(counts()) == 0
    assert reg.pauses_needed(counts(retreat=3)) == 4
    assert reg.pauses_needed(counts(gaze_vertical=2)) == 1
    assert reg.pauses_needed(counts(retreat=1, gaze_horizontal=1, gaze_vertical=1)) == 3


def test_a_plugin_kind_without_a_synth_part_is_left_out(monkeypatch):
    fake.install(monkeypatch)  # its distance reads more hesitant: still not varied
    assert fake.NAME not in reg.kind_recipes()
    assert all(kind != fake.NAME for kind, _plane in reg.slots())
    assert not any(d.kind == fake.NAME for d in reg.descriptors())
    r = recipe(State.HESITANT, 0.8)
    assert "lunge_distance" not in r.notes and r.node(fake.NAME) is None


def test_a_plugin_synth_part_is_merged(monkeypatch):
    fake.install(monkeypatch, synth=SimpleNamespace(
        spans={State.HESITANT: {"distance": 1.5}}, min_count=1))
    entry = reg.kind_recipes()[fake.NAME]
    assert entry.min_count == 1 and entry.planes == (None,)
    assert reg.slots()[-1] == (fake.NAME, None)
    assert reg.span_of(State.HESITANT, fake.NAME, "distance") == 1.5
    assert reg.spans()[State.HESITANT][(fake.NAME, "distance")] == 1.5
    assert {d.name for d in reg.descriptors()} == set(REGISTRY) | {
        d.name for d in fake.DESCRIPTORS}
    # the study's stimuli hold no lunge: synthesis goes on without it
    assert recipe(State.HESITANT, 0.8).node(fake.NAME) is None


def test_a_malformed_synth_part_is_left_out(monkeypatch):
    fake.install(monkeypatch, synth=SimpleNamespace(spans={"hesitant": {"distance": "x"}}))
    assert fake.NAME not in reg.kind_recipes()
