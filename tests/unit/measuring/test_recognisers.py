"""The measurement's registry keyed by kind (aou_dsl/measuring/recognisers.py): the six
built-in kinds, a plugin's measure pass claiming its episodes from the measured ones (in
a list of episodes, and in a motion compiled by aou), its descriptors aggregated after
the eleven, and K801/K802 where a plugin's part cannot be used."""

from __future__ import annotations

from dataclasses import replace

import pytest

from aou_dsl import api
from aou_dsl.core.codes import K801, K802
from aou_dsl.core.diagnostics import AouError
from aou_dsl.lang.descriptors import REGISTRY, EpisodeValues, derive
from aou_dsl.lang.primitives import APPROACH, GAZE, PAUSE, RETREAT, SHIVER, TILT
from aou_dsl.measuring import recognisers
from aou_dsl.measuring.measured import measure
from aou_dsl.measuring.verdict import judge
from tests.unit.measuring import fake_plugin as fake
from tests.unit.measuring.fake_plugin import COUNTER


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    path = tmp_path_factory.mktemp("counter") / "counter.aou"
    path.write_text(COUNTER)
    res = api.compile(str(path))
    assert res.trajectory is not None, [d.message for d in res.diagnostics]
    return path, res


def _ep(kind, t0, t1, **values):
    return EpisodeValues(kind, t0, t1, values)


#: Pause, counter-movement, approach, pause, retreat, pause, retreat, approach (a retreat
#: straight into an approach again, of 3 cm).
SEQUENCE = [
    _ep(PAUSE, 0.0, 1.0, duration=1.0),
    _ep(RETREAT, 1.0, 1.5, distance=0.01, peak_acceleration=0.1),
    _ep(APPROACH, 1.5, 2.5, distance=0.05, peak_acceleration=0.1),
    _ep(PAUSE, 2.5, 3.5, duration=1.0),
    _ep(RETREAT, 3.5, 4.0, distance=0.02, peak_acceleration=0.2),
    _ep(PAUSE, 4.0, 5.0, duration=1.0),
    _ep(RETREAT, 5.0, 5.5, distance=0.03, peak_acceleration=0.3),
    _ep(APPROACH, 5.5, 6.5, distance=0.08, peak_acceleration=0.1),
]


def test_the_registry_holds_the_six_built_in_kinds_and_nothing_else(monkeypatch):
    fake.no_plugins(monkeypatch)
    kinds = {APPROACH, PAUSE, RETREAT, GAZE, TILT, SHIVER}
    assert set(recognisers.BUILTIN) == kinds
    assert recognisers.recognisers() == recognisers.BUILTIN
    assert all(r.part is None and r.source == "aou" for r in recognisers.BUILTIN.values())
    # each built-in's values are the keys its descriptors read
    for d in REGISTRY.values():
        assert d.is_count or d.key in recognisers.BUILTIN[d.kind].keys, d.name
    assert recognisers.moved_along(True) == APPROACH
    assert recognisers.moved_along(False) == RETREAT


def test_measured_episodes_are_of_the_registry_s_kinds(monkeypatch, compiled):
    fake.no_plugins(monkeypatch)
    _, res = compiled
    m = measure(res.trajectory, uncertainty=False)
    assert [e.kind for e in m.episodes] == [APPROACH, PAUSE, RETREAT, APPROACH, PAUSE,
                                            RETREAT, PAUSE]
    assert m.extra == {}
    assert list(m.to_json()["descriptors"]) == list(REGISTRY)


def test_a_plugin_pass_claims_its_episodes_from_a_measured_sequence(monkeypatch):
    fake.install(monkeypatch, measure=fake.Claim())
    assert fake.KIND in recognisers.recognisers()
    assert recognisers.recognisers()[fake.KIND].keys == ("distance",)
    eps, diags = recognisers.claimed(SEQUENCE)
    assert diags == []
    assert [e.kind for e in eps] == [PAUSE, fake.KIND, APPROACH, PAUSE, RETREAT, PAUSE,
                                     fake.KIND, APPROACH]
    assert [e.values for e in eps if e.kind == fake.KIND] == [SEQUENCE[1].values,
                                                              SEQUENCE[6].values]
    extra = recognisers.extra_values(eps)
    assert list(extra) == [fake.DISTANCE.name, fake.COUNT.name]
    assert extra[fake.COUNT.name] == 2
    assert extra[fake.DISTANCE.name] == pytest.approx(0.02)  # median of 1 and 3 cm
    # the eleven no longer see the claimed episodes: one retreat, between two pauses
    d = derive(eps)
    assert d["retreat_count"] == 1 and d["retreat_acceleration"] == pytest.approx(0.2)


def test_a_plugin_pass_claims_its_episode_in_a_compiled_motion(monkeypatch, compiled):
    fake.install(monkeypatch, measure=fake.Claim())
    _, res = compiled
    m = measure(res.trajectory, uncertainty=False)
    assert [e.kind for e in m.episodes] == [APPROACH, PAUSE, fake.KIND, APPROACH, PAUSE,
                                            RETREAT, PAUSE]
    assert m.extra[fake.COUNT.name] == 1
    assert m.extra[fake.DISTANCE.name] == pytest.approx(0.01, abs=1e-3)
    assert m.descriptors["retreat_count"] == 1
    assert m.descriptors["retreat_distance"] == pytest.approx(0.02, abs=1e-3)
    doc = m.to_json()
    assert list(doc["descriptors"]) == [*REGISTRY, fake.DISTANCE.name, fake.COUNT.name]
    assert doc["descriptors"][fake.COUNT.name] == 1
    assert [e["kind"] for e in doc["episodes"]].count(fake.KIND) == 1


class _Raises:
    def claim(self, episodes):
        raise ValueError("boom")


class _Garbage:
    def claim(self, episodes):
        return [*episodes, "not an episode"]


class _Unordered:
    def claim(self, episodes):
        return list(reversed(episodes))


@pytest.mark.parametrize("part", [_Raises(), _Garbage(), _Unordered()],
                         ids=["raises", "garbage", "unordered"])
def test_a_pass_that_cannot_be_used_is_left_out_with_k801(monkeypatch, part):
    fake.install(monkeypatch, measure=part)
    eps, diags = recognisers.claimed(SEQUENCE)
    assert eps == SEQUENCE
    (d,) = diags
    assert d.code == K801 and fake.KIND in d.message and fake.SOURCE in d.message
    assert d.fields["stage"] == recognisers.LAYER


def test_a_plugin_kind_without_a_measure_part_gets_k802(monkeypatch):
    fake.install(monkeypatch)  # no measure part
    assert fake.KIND not in recognisers.recognisers()
    assert recognisers.missing_part({APPROACH, PAUSE}, {}) == []
    (d,) = recognisers.missing_part({APPROACH, fake.KIND}, {})
    assert d.code == K802
    assert fake.KIND in d.message and fake.SOURCE in d.message and "measure" in d.message
    assert d.fields == {"kind": fake.KIND, "plugin": fake.SOURCE, "stage": "measure"}


def test_a_measure_part_without_claim_is_no_measure_part(monkeypatch):
    fake.install(monkeypatch, measure=object())
    assert fake.KIND not in recognisers.recognisers()
    (d,) = recognisers.missing_part({fake.KIND}, {})
    assert d.code == K802 and "claim" in d.message


def test_judging_a_file_that_uses_an_unmeasurable_plugin_kind_says_k802_not_fail(
        monkeypatch, compiled):
    """The file's counter-movement is of the plugin's kind (its episode relabelled in
    the lint, as a loaded plugin's kind would lay out): the recording cannot be
    judged."""
    fake.install(monkeypatch)
    path, res = compiled
    lint = res.lint
    eps = tuple(replace(e, kind=fake.KIND) if i == 2 else e
                for i, e in enumerate(lint.timeline.episodes))
    lint = replace(lint, timeline=replace(lint.timeline, episodes=eps))
    with pytest.raises(AouError) as err:
        judge(res.trajectory, lint)
    (d,) = err.value.diagnostics
    assert d.code == K802 and d.span == eps[2].span
    # with no plugin kind in the file, the same recording is judged and passes
    fake.no_plugins(monkeypatch)
    assert judge(res.trajectory, res.lint).result == "pass"


def test_judged_rows_end_with_the_plugin_s_descriptors(monkeypatch, compiled):
    """A file that declares no counter-movement, its motion showing one that the
    plugin's pass claims: the plugin's count fails (declared 0, measured 1), its distance
    too (declared absent); the eleven pass as before."""
    fake.install(monkeypatch, measure=fake.Claim())
    _, res = compiled
    v = judge(res.trajectory, res.lint)
    assert [r.name for r in v.rows] == [*REGISTRY, fake.DISTANCE.name, fake.COUNT.name]
    rows = {r.name: r for r in v.rows}
    assert (rows[fake.COUNT.name].declared, rows[fake.COUNT.name].measured) == (0, 1)
    assert rows[fake.DISTANCE.name].declared is None
    assert {r.name for r in v.failed} == {fake.DISTANCE.name, fake.COUNT.name}
    assert all(rows[name].ok for name in REGISTRY)


def test_a_noisy_recording_gives_the_plugin_s_descriptors_an_interval(monkeypatch, compiled):
    """Re-noised copies read the plugin's descriptors as they read the eleven."""
    import numpy as np

    fake.install(monkeypatch, measure=fake.Claim())
    _, res = compiled
    tr = res.trajectory
    q = np.asarray(tr.q, float)
    noisy = tr.with_(q=q + np.random.default_rng(3).normal(0.0, 2e-5, q.shape), qd=None,
                     qdd=None)
    m = measure(noisy)
    assert list(m.uncertainty) == [*REGISTRY, fake.DISTANCE.name, fake.COUNT.name]
    count, dist = m.uncertainty[fake.COUNT.name], m.uncertainty[fake.DISTANCE.name]
    assert (count.low, count.high) == (1, 1)
    assert dist.low < m.extra[fake.DISTANCE.name] < dist.high
    assert dist.high - dist.low < 2e-3
