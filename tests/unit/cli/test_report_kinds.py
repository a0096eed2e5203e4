"""The command line's reports of kinds (aou_dsl/cli/report.py): ``aouc measure`` prints a
plugin's descriptors after the eleven, and ``aouc explain`` says what moves in a plugin
kind's episode from its own values, the built-ins' lines unchanged."""

from __future__ import annotations

from dataclasses import replace

import pytest

from aou_dsl import api
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.measuring.measured import measure
from tests.unit.measuring import fake_plugin as fake
from tests.unit.measuring.fake_plugin import COUNTER


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    path = tmp_path_factory.mktemp("report") / "counter.aou"
    path.write_text(COUNTER)
    return api.compile(str(path))


def test_measure_prints_the_plugin_s_descriptors_after_the_eleven(monkeypatch, compiled):
    from aou_dsl.cli.report import format_measured

    fake.install(monkeypatch, measure=fake.Claim())
    m = measure(compiled.trajectory, uncertainty=False)
    lines = format_measured("counter.json", "panda", m).splitlines()
    names = [ln.split()[0] for ln in lines[1:] if ln.startswith("  ") and not
             ln.startswith("  C-V") and not ln.startswith("  line")]
    assert names == [*REGISTRY, fake.DISTANCE.name, fake.COUNT.name]
    dist = next(ln for ln in lines if ln.split()[0] == fake.DISTANCE.name).split()
    assert float(dist[1]) == pytest.approx(0.01, abs=1e-3) and dist[-1] == "m"
    assert next(ln for ln in lines if ln.split()[0] == fake.COUNT.name).split()[1:] == ["1"]


def test_measure_without_plugins_prints_the_eleven_only(monkeypatch, compiled):
    from aou_dsl.cli.report import format_measured

    fake.no_plugins(monkeypatch)
    text = format_measured("counter.json", "panda", measure(compiled.trajectory,
                                                            uncertainty=False))
    assert fake.KIND not in text
    assert all(name in text for name in REGISTRY)


def test_explain_says_where_a_plugin_kind_s_episode_goes(compiled):
    from aou_dsl.cli.report import format_timeline

    lint = compiled.lint
    eps = tuple(replace(e, kind=fake.KIND) if i == 2 else e
                for i, e in enumerate(lint.timeline.episodes))
    before = format_timeline(lint.behaviour, lint.cv, lint.timeline).splitlines()
    after = format_timeline(lint.behaviour, lint.cv,
                            replace(lint.timeline, episodes=eps)).splitlines()
    # the kind column widens to the plugin's longer name, for every line alike
    assert [ln.index("start") for ln in (before[2], after[2])] == \
        [5 + 9 + 3, 5 + len(fake.KIND) + 1 + 3]
    assert [ln.split()[1] for ln in after[3:-1]] == [e.kind for e in eps]
    end = after[2].index("start") + len("start") - 1  # each start time ends under it
    assert all(ln[end] == "s" and ln[end - 1].isdigit() for ln in after[3:-1])
    changed = [(a, b) for a, b in zip(before[3:], after[3:], strict=True)
               if a.split() != b.split()]
    assert len(changed) == 1
    was, now = changed[0]
    assert "retreat" in was and "(a=0.1 m/s^2)" in was
    d0, d1 = eps[2].start.d, eps[2].end.d
    assert f"{fake.KIND}" in now and f"distance {d0:.3f} -> {d1:.3f} m" in now
    assert "(a=" not in now  # not a built-in's line
