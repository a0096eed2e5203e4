"""The studio's controls registry: every built-in kind's colour, a plugin kind's colour
from its ``studio`` part or the default, and a slider for each plugin descriptor."""

from __future__ import annotations

import contextlib
from types import SimpleNamespace
from typing import Any

from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.primitives import KINDS
from aou_dsl.studio import kind_controls as reg
from aou_dsl.studio.controls import Sliders, slider_range
from aou_dsl.studio.plots import timeline
from tests.unit import kind_plugin_fake as fake

BUILTIN = [k for k in KINDS if k != fake.NAME]


class _Gui:
    """The part of viser's GUI the sliders use: what was added, with its arguments."""

    def __init__(self) -> None:
        self.sliders: dict[str, tuple] = {}

    def add_folder(self, label: str) -> contextlib.AbstractContextManager:
        return contextlib.nullcontext()

    def add_slider(self, name: str, lo: Any, hi: Any, step: Any, value: Any,
                   hint: str = "") -> Any:
        self.sliders[name] = (lo, hi, step, value, hint)
        return SimpleNamespace(min=lo, max=hi, value=value, remove=lambda: None,
                               on_update=lambda f: None)


def _sliders(values: dict) -> dict[str, tuple]:
    gui = _Gui()
    Sliders(SimpleNamespace(gui=gui), lambda v: None).show(values)
    return gui.sliders


def test_every_builtin_kind_has_its_own_colour_and_every_descriptor_a_slider():
    colours = [reg.colour_of(k) for k in BUILTIN]
    assert len(set(colours)) == len(BUILTIN) and reg.DEFAULT_COLOUR not in colours
    assert set(reg.EPISODE_COLOURS) == set(BUILTIN)
    assert reg.colour_of("no kind") == reg.DEFAULT_COLOUR
    for name, d in REGISTRY.items():
        lo, hi, step = reg.range_of(name)
        assert lo < hi and 0 < step and d.unit in reg.RANGES


def test_the_timeline_draws_each_kind_in_its_colour():
    r, g, b = reg.colour_of(BUILTIN[0])
    assert f"rgb({r},{g},{b})" in timeline([(BUILTIN[0], 0.0, 1.0)], 0.0, 1.0, 0.5)


def test_a_plugin_kind_without_a_studio_part_gets_the_default_and_its_sliders(monkeypatch):
    fake.install(monkeypatch)
    assert reg.colour_of(fake.NAME) == reg.DEFAULT_COLOUR
    assert set(reg.descriptors()) == set(REGISTRY) | {d.name for d in fake.DESCRIPTORS}
    made = _sliders({"lunge_distance": 0.3, "lunge_count": 2})
    lo, hi, step, value, hint = made["lunge_distance"]
    assert (lo, step) == reg.RANGES["m"][::2] and hi == 0.3 and value == 0.3  # widened
    assert hint == "lunge_distance [m]"
    assert made["lunge_count"] == (0, 10, 1, 2, "lunge_count [count]")


def test_a_plugin_studio_part_gives_its_colour_and_ranges(monkeypatch):
    fake.install(monkeypatch, studio=SimpleNamespace(
        colour=(10, 20, 30), ranges={"lunge_distance": (0.001, 0.05, 0.001)}))
    assert reg.colour_of(fake.NAME) == (10, 20, 30)
    assert reg.kind_controls()[fake.NAME].colour == (10, 20, 30)
    assert "rgb(10,20,30)" in timeline([(fake.NAME, 0.0, 1.0)], 0.0, 1.0, 0.5)
    assert slider_range("lunge_distance", 0.01) == (0.001, 0.05, 0.001)
    assert slider_range("lunge_count", 3) == reg.RANGES[""]


def test_a_malformed_studio_part_falls_back_to_the_default(monkeypatch):
    fake.install(monkeypatch, studio=SimpleNamespace(colour=(300, 0, 0)))
    assert reg.colour_of(fake.NAME) == reg.DEFAULT_COLOUR
    fake.install(monkeypatch, studio=SimpleNamespace(colour=(1, 2, 3), ranges={"x": (1, 0, 1)}))
    assert reg.colour_of(fake.NAME) == reg.DEFAULT_COLOUR
