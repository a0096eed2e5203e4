"""A primitive kind from another package: KINDS takes it in, or says why not.

Each test installs a made-up plugin (``tests/unit/fake_plugins.py``) through a real
``*.dist-info`` folder on ``sys.path``, as pip would, so the loader reads it through
``importlib.metadata`` like any installed package.
"""

from __future__ import annotations

import pytest

from aou_dsl.core.codes import K801, K803, V101
from aou_dsl.lang.cv import CHANNELS, Composition, composition
from aou_dsl.lang.descriptors import REGISTRY, EpisodeValues, derive, every_descriptor
from aou_dsl.lang.linter import lint_source
from aou_dsl.lang.primitives import BUILTIN_KINDS, KINDS, PAUSE, plugin_problems

from ...conftest import BEHAVIOURS
from ..fake_plugins import LURCH, fresh_plugins, install  # noqa: F401

BUILTINS = {"approach", "pause", "retreat", "gaze", "tilt", "shiver"}
pytestmark = pytest.mark.usefixtures("fresh_plugins")


def _lurch(tmp_path, monkeypatch, source=LURCH, entry="lurch", module="aou_fake_lurch",
           dist="aou-lurch"):
    install(tmp_path / module, monkeypatch, entry=entry, module=module, source=source,
            dist=dist)


def test_kinds_are_the_six_builtins_without_plugins(monkeypatch):
    monkeypatch.setenv("AOU_NO_PLUGINS", "1")
    assert set(KINDS) == set(BUILTIN_KINDS) == BUILTINS
    assert len(KINDS) == 6 and "lurch" not in KINDS


def test_a_plugin_kind_joins_kinds_and_its_descriptors_the_eleven(tmp_path, monkeypatch):
    _lurch(tmp_path, monkeypatch)
    assert "lurch" in KINDS and list(KINDS)[:6] == list(BUILTIN_KINDS)
    assert KINDS["lurch"].name == "lurch" and type(KINDS["lurch"]).__name__ == "LurchKind"
    assert set(BUILTIN_KINDS) == BUILTINS  # the built-ins stay six
    every = every_descriptor()
    assert list(every)[:11] == list(REGISTRY)
    assert list(every)[11:] == ["lurch_distance", "lurch_count"]
    assert plugin_problems() == ()
    # the measured side derives them like the eleven: counts and medians of its episodes
    got = derive([EpisodeValues(PAUSE, 0, 1, {"duration": 1.0}),
                  EpisodeValues("lurch", 1, 2, {"distance": 0.02}),
                  EpisodeValues("lurch", 2, 3, {"distance": 0.04})])
    assert got["lurch_count"] == 2 and got["lurch_distance"] == pytest.approx(0.03)


def test_no_plugins_switch_hides_an_installed_plugin(tmp_path, monkeypatch):
    _lurch(tmp_path, monkeypatch)
    assert "lurch" in KINDS
    monkeypatch.setenv("AOU_NO_PLUGINS", "1")
    assert "lurch" not in KINDS and len(every_descriptor()) == 11


def test_a_plugin_kind_feeds_the_cv_channels_its_table_names(tmp_path, monkeypatch):
    _lurch(tmp_path, monkeypatch)
    comp = composition([EpisodeValues("lurch", 0, 1, {"distance": 0.05}),
                        EpisodeValues("lurch", 1, 2, {"distance": 0.03})])
    assert comp == Composition(extent=pytest.approx(0.08))
    assert set(CHANNELS) == set(Composition.__dataclass_fields__)


def test_a_plugin_kind_named_like_a_builtin_is_k803_and_the_builtin_keeps_it(
        tmp_path, monkeypatch):
    _lurch(tmp_path, monkeypatch, source=LURCH.replace('NAME = "lurch"', 'NAME = "pause"'),
           entry="pause", module="aou_fake_pause", dist="aou-pause")
    problems = plugin_problems()
    assert [(p.code, p.name, p.source) for p in problems] == [(K803, "pause",
                                                                "aou-pause 0.1")]
    assert type(KINDS["pause"]).__name__ == "PauseKind" and len(KINDS) == 6
    # a file that uses `pause` is told, once, where it first uses it
    text = (BEHAVIOURS / "fearful.aou").read_text(encoding="utf-8")
    line = next(i for i, ln in enumerate(text.splitlines(), 1) if ln.startswith("pause"))
    res = lint_source(text, "fearful.aou")
    k803 = [d for d in res.diagnostics if d.code == K803]
    assert len(k803) == 1 and k803[0].span.line == line and "aou-pause" in k803[0].message
    assert res.ok  # a warning: the file still lints
    # one that does not, is not
    res = lint_source("behaviour b\nrobot ur5\nretreat 2cm\n", "b.aou")
    assert not [d for d in res.diagnostics if d.code == K803]


def test_a_plugin_whose_import_raises_is_k801_and_aou_goes_on(tmp_path, monkeypatch):
    _lurch(tmp_path, monkeypatch, source="raise RuntimeError('no motor driver')\n",
           module="aou_fake_broken", dist="aou-broken")
    assert set(KINDS) == BUILTINS
    (p,) = plugin_problems()
    assert p.code == K801 and p.name == "lurch" and "no motor driver" in p.why
    res = lint_source("behaviour b\nrobot ur5\nlurch 2cm\n", "b.aou")
    codes = sorted(d.code for d in res.diagnostics)
    assert codes == [K801, V101], codes
    v101 = next(d for d in res.diagnostics if d.code == V101)
    assert "cannot be used" in v101.message and "no motor driver" in v101.message
    for path in sorted(BEHAVIOURS.glob("*.aou")):  # the shipped behaviours lint as before
        res = lint_source(path.read_text(encoding="utf-8"), str(path))
        assert res.ok and not [d for d in res.diagnostics if d.code in (K801, K803)]


@pytest.mark.parametrize("change, why", [
    (("kind = LurchKind()", "kind = object()"), "not an instance of aou's Kind"),
    (("kind = LurchKind()", "kind = LurchKind()\nkind.name = 'lunge'"), "named `lunge`"),
    (('{"extent": ("distance", "sum")}', '{"courage": ("distance", "sum")}'),
     "the channel `courage`"),
    (('{"extent": ("distance", "sum")}', '{"extent": ("distance", "mean")}'),
     "not (value key"),
])
def test_a_malformed_kind_part_is_k801(tmp_path, monkeypatch, change, why):
    _lurch(tmp_path, monkeypatch, source=LURCH.replace(*change))
    assert "lurch" not in KINDS
    (p,) = plugin_problems()
    assert p.code == K801 and why in p.why, p.why


def test_a_plugin_descriptor_with_a_taken_name_is_k803(tmp_path, monkeypatch):
    _lurch(tmp_path, monkeypatch, source=LURCH.replace('"lurch_count"', '"pause_count"'))
    from aou_dsl.lang.descriptors import descriptor_problems

    assert "lurch" in KINDS
    assert [(p.code, p.name) for p in descriptor_problems()] == [(K803, "lurch")]
    assert list(every_descriptor())[11:] == ["lurch_distance"]
    assert every_descriptor()["pause_count"] is REGISTRY["pause_count"]


def test_an_unknown_keyword_without_a_plugin_is_v101_saying_so(monkeypatch):
    monkeypatch.setenv("AOU_NO_PLUGINS", "1")
    res = lint_source("behaviour b\nrobot ur5\nlurch 2cm\n", "b.aou")
    (d,) = res.diagnostics
    assert d.code == V101 and "no installed plugin gives it" in d.message
