"""The editor's texts registry: every built-in kind, a plugin kind completed from its
kind object alone, and a plugin's ``editor`` part merged into completion and hover."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

pytest.importorskip("lsprotocol", reason="the lsp extra is not installed")
from lsprotocol import types

from aou_dsl.core.units import Dim, units_for
from aou_dsl.editor import kind_texts as reg
from aou_dsl.editor.completion import complete
from aou_dsl.editor.convert import Text
from aou_dsl.editor.hover import describe, descriptor_for
from aou_dsl.editor.state import Document
from aou_dsl.lang.primitives import KINDS
from tests.unit import kind_plugin_fake as fake

BUILTIN = [k for k in KINDS if k != fake.NAME]


def _labels(text: str) -> list[str]:
    lines = text.split("\n")
    doc = Document("file:///x.aou", "x.aou", Text(text))
    pos = types.Position(line=len(lines) - 1, character=len(lines[-1]))
    return [i.label for i in complete(doc, pos).items]


def _units(number: str, dim: Dim) -> list[str]:
    return [f"{number}{u}" for u in units_for(dim)]


def test_every_builtin_kind_has_texts_that_agree_with_its_usage():
    texts = reg.kind_texts()
    assert set(BUILTIN) <= set(texts)
    for name in BUILTIN:  # the positional quantity the kind's own usage names
        assert texts[name].positional is reg._from_usage(KINDS[name].usage), name
        assert texts[name].positional is not None
        for plane in texts[name].planes:  # the planes its usage offers
            assert plane in KINDS[name].usage


def test_a_plugin_kind_without_an_editor_part_completes_from_its_kind(monkeypatch):
    assert "lunge" not in _labels("")
    fake.install(monkeypatch)
    assert "lunge" in _labels("")
    keys = _labels("lunge 1cm ")
    assert {f"{k}=" for k in fake.LungeKind.keys} <= set(keys) and "x2" in keys
    assert _labels("lunge 5") == _units("5", Dim.LENGTH)  # its usage says DIST
    assert _labels("lunge 1cm a=0.") == _units("0.", Dim.ACCEL)
    # hover on its count: the descriptor, with a line saying whose it is
    d = descriptor_for(fake.NAME, "x")
    assert d is not None and d.name == "lunge_count"
    assert "`lunge`" in describe(d)


def test_a_plugin_editor_part_is_merged(monkeypatch):
    fake.install(monkeypatch, editor=SimpleNamespace(
        positional=Dim.TIME, planes=("up", "down"), words={"until": "until DURATION"},
        word_dims={"until": Dim.ANGLE},
        definitions={"lunge_distance": "how far one lunge goes"}))
    assert _labels("lunge 5") == _units("5", Dim.TIME)
    assert _labels("lunge ") == ["up", "down"]
    assert "until" in _labels("lunge 1s ")
    assert "until" not in _labels("lunge 1s until 2s ")
    assert _labels("lunge 1s until 3") == _units("3", Dim.ANGLE)
    # a kind with planes has one descriptor per plane (a gaze's): lunge has none per plane
    assert descriptor_for(fake.NAME, "value", "up") is None
    fake.install(monkeypatch, editor=SimpleNamespace(
        positional=Dim.LENGTH, definitions={"lunge_distance": "how far one lunge goes"}))
    d = descriptor_for(fake.NAME, "value")
    assert d is not None and d.name == "lunge_distance"
    assert "how far one lunge goes" in describe(d)


def test_a_malformed_editor_part_falls_back_to_the_kind(monkeypatch):
    fake.install(monkeypatch, editor=SimpleNamespace(positional="metres"))
    assert reg.texts_of(fake.NAME) == reg.KindTexts(Dim.LENGTH)
    assert _labels("lunge 5") == _units("5", Dim.LENGTH)
