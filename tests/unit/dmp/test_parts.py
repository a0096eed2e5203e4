"""The DMP parts registry: every built-in kind, a plugin's ``dmp`` part merged, and a
plugin kind without one refused with K802 (never a traceback)."""

from __future__ import annotations

import argparse
from types import SimpleNamespace

import numpy as np
import pytest

from aou_dsl.core.diagnostics import AouError, Severity, Span
from aou_dsl.dmp import parts
from aou_dsl.dmp.parts import Scaling, Shape
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.primitives import KINDS, PAUSE
from tests.unit import kind_plugin_fake as fake

BUILTIN = [k for k in KINDS if k != fake.NAME]
WHERE = Span.whole_file("x.aou")


def _part(shape: str = "move", **more: object) -> SimpleNamespace:
    return SimpleNamespace(shape=shape, parameters={
        "distance": "start_y/goal_y and forcing weights (amplitude scaling)",
        "": "the parts (fixed)"}, **more)


def _pose() -> dict:
    return {"position": [0.3, 0.0, 0.2], "quaternion": [1.0, 0.0, 0.0, 0.0]}


def _entry(kind: str, file: str | None = None, values: dict | None = None) -> dict:
    return {"kind": kind, "duration": 1.0, "file": file, "start": _pose(), "end": _pose(),
            "lead": 0.0, "values": values or {}}


def test_every_builtin_kind_has_a_part_and_every_descriptor_a_manifest_line():
    kinds = parts.dmp_kinds()
    assert set(BUILTIN) <= set(kinds)
    for name in BUILTIN:  # a translation moves the hand along a line: a fitted DMP
        if KINDS[name].translation:
            assert kinds[name].shape is Shape.MOVE, name
    from aou_dsl.synth.recipe import descriptor

    named = [descriptor(kind, key).name for (kind, key), _text in parts.parameter_lines()]
    assert sorted(named) == sorted(REGISTRY)
    # what a rollout may pin: each kind whose peak acceleration is a descriptor
    assert set(parts.pinnable()) == {d.kind for d in REGISTRY.values()
                                     if d.key == "peak_acceleration"}


def test_a_plugin_part_is_merged_into_every_use(monkeypatch):
    fake.install(monkeypatch, dmp=_part(scaling={"distance": "space",
                                                 "peak_acceleration": "peak"}))
    entry = parts.dmp_kinds()[fake.NAME]
    assert entry.shape is Shape.MOVE and entry.scaling["distance"] is Scaling.SPACE
    assert fake.NAME in parts.moves() and fake.NAME in parts.pinnable()
    assert parts.dmp_kind(fake.NAME, WHERE) == entry
    assert parts.parameter_lines()[-2:] == [
        ((fake.NAME, "distance"), "start_y/goal_y and forcing weights (amplitude scaling)"),
        ((fake.NAME, ""), "the parts (fixed)")]
    from aou_dsl.dmp.manifest import _parameters

    assert _parameters()["lunge_distance"].startswith("start_y/goal_y")
    # a rollout to a goal twice as far predicts the plugin's distance twice as long
    from aou_dsl.dmp.rollout import predict

    seq = SimpleNamespace(descriptors={"lunge_distance": 0.02, "lunge_count": 1,
                                       "lunge_acceleration": 0.5})
    out = predict(seq, 2.0, 2.0, {}, ())  # type: ignore[arg-type]
    assert out == {"lunge_distance": pytest.approx(0.04), "lunge_count": 1,
                   "lunge_acceleration": pytest.approx(0.5 * 2.0 / 2.0 ** 2)}
    pinned = predict(seq, 2.0, 2.0, {}, ("lunge_acceleration",))  # type: ignore[arg-type]
    assert pinned["lunge_acceleration"] == pytest.approx(0.5)


def test_the_schema_accepts_a_loaded_plugin_kind_and_refuses_unknown_kinds(monkeypatch):
    from aou_dsl.dmp.schema import Where
    from aou_dsl.dmp.schema import _entry as check

    w = Where("x.dmp/manifest.json")
    with pytest.raises(AouError) as no_plugin:
        check(_entry(fake.NAME, "parts/01-lunge.json"), w, "parts[0]")
    assert no_plugin.value.diagnostics[0].code == "D602"
    fake.install(monkeypatch, dmp=_part())
    assert check(_entry(fake.NAME, "parts/01-lunge.json"), w, "parts[0]")["kind"] == "lunge"
    with pytest.raises(AouError) as unknown:
        check(_entry("os.system"), w, "parts[0]")
    assert unknown.value.diagnostics[0].code == "D602"
    assert "lunge" in unknown.value.diagnostics[0].message


def test_a_plugin_hold_has_no_part_file(monkeypatch):
    from aou_dsl.dmp.schema import Where
    from aou_dsl.dmp.schema import _entry as check

    fake.install(monkeypatch, dmp=_part("hold"))
    with pytest.raises(AouError) as held:
        check(_entry(fake.NAME, "parts/01-lunge.json"), Where("m.json"), "parts[0]")
    assert "must be null" in held.value.diagnostics[0].message


def test_a_plugin_kind_without_a_dmp_part_is_k802(monkeypatch):
    fake.install(monkeypatch)
    with pytest.raises(AouError) as err:
        parts.dmp_kind(fake.NAME, WHERE)
    d = err.value.diagnostics[0]
    assert d.code == "K802" and d.severity is Severity.ERROR
    assert "`lunge`" in d.message and fake.SOURCE in d.message and "DMP" in d.message
    assert fake.NAME not in parts.dmp_kinds()
    # the export says so before any work, for a trajectory holding one of its episodes
    from aou_dsl.dmp.export import to_dmp

    tr = SimpleNamespace(episodes=[(PAUSE, 0.0, 1.0), (fake.NAME, 1.0, 2.0)],
                         goal=np.zeros(3), path="x.json", robot="ur5", ee_frame=None)
    with pytest.raises(AouError) as export:
        to_dmp(tr)
    assert export.value.diagnostics[0].code == "K802"


def test_a_malformed_dmp_part_is_k801_naming_why(monkeypatch):
    fake.install(monkeypatch, dmp=_part("wobble"))
    with pytest.raises(AouError) as err:
        parts.dmp_kind(fake.NAME, WHERE)
    d = err.value.diagnostics[0]
    assert d.code == "K801" and d.severity is Severity.ERROR and "wobble" in d.message
    fake.install(monkeypatch, dmp=_part(scaling={"distance": "sideways"}))
    with pytest.raises(AouError, match="scaling"):
        parts.dmp_kind(fake.NAME, WHERE)


def test_pin_choices_come_from_the_registry(monkeypatch):
    from aou_dsl.cli.actions_args import dmp_parser

    def parse(*argv: str) -> argparse.Namespace:
        top = argparse.ArgumentParser(exit_on_error=False)
        dmp_parser(top.add_subparsers(dest="command"))
        return top.parse_args(["dmp", "roll", "x.dmp", *argv])

    for kind in parts.pinnable():
        assert parse("--pin", kind).pin == [kind]
    with pytest.raises(SystemExit):
        parse("--pin", fake.NAME)
    fake.install(monkeypatch, dmp=_part(scaling={"peak_acceleration": "peak"}))
    assert parse("--pin", fake.NAME).pin == [fake.NAME]
