"""Plots' colours and labels keyed by kind (aou_dsl/media/kind_labels.py): the six
built-in kinds, a plugin's media part, and the default for a plugin that gives none."""

from __future__ import annotations

import re
from types import SimpleNamespace

import pytest

from aou_dsl.core.plugins import Plugin
from aou_dsl.lang.primitives import APPROACH, GAZE, PAUSE, RETREAT, SHIVER, TILT
from aou_dsl.media import kind_labels

KIND = "anticipate"


def _install(monkeypatch, media=None) -> None:
    parts = {"kind": object()} | ({} if media is None else {"media": media})
    plugin = Plugin(KIND, "aou-fake 0.1", parts)
    monkeypatch.setattr(kind_labels, "_plugins", SimpleNamespace(plugins=lambda: (plugin,)))


def test_the_six_built_in_kinds_have_their_own_colours():
    kinds = {APPROACH, PAUSE, RETREAT, GAZE, TILT, SHIVER}
    assert set(kind_labels.BUILTIN) == kinds
    colours = [lb.colour for lb in kind_labels.BUILTIN.values()]
    assert len(set(colours)) == 6 and kind_labels.DEFAULT_COLOUR not in colours
    assert all(re.fullmatch(r"#[0-9a-f]{6}", c) for c in colours)
    assert all(lb.label == k for k, lb in kind_labels.BUILTIN.items())


def test_a_plugin_s_media_part_gives_its_colour_and_label(monkeypatch):
    _install(monkeypatch, SimpleNamespace(colour="#123abc", label="anticipation"))
    got = kind_labels.labels()[KIND]
    assert (got.colour, got.label) == ("#123abc", "anticipation")
    assert kind_labels.label_of(KIND) == got


@pytest.mark.parametrize("media", [None, SimpleNamespace(), SimpleNamespace(
    colour="red; drop", label=""), SimpleNamespace(colour=3, label=None)],
    ids=["no part", "empty part", "bad colour", "wrong types"])
def test_a_plugin_without_a_usable_media_part_gets_the_default(monkeypatch, media):
    _install(monkeypatch, media)
    got = kind_labels.labels()[KIND]
    assert (got.colour, got.label) == (kind_labels.DEFAULT_COLOUR, KIND)


def test_a_plugin_cannot_recolour_a_built_in_kind(monkeypatch):
    plugin = Plugin(PAUSE, "aou-fake 0.1", {"kind": object(),
                                            "media": SimpleNamespace(colour="#000000")})
    monkeypatch.setattr(kind_labels, "_plugins", SimpleNamespace(plugins=lambda: (plugin,)))
    assert kind_labels.labels()[PAUSE] == kind_labels.BUILTIN[PAUSE]


def test_the_profile_figure_shades_each_kind_in_its_colour(monkeypatch):
    """The figure draws what the table says: a plugin kind's episode in its colour, a
    kind nothing knows in the default."""
    pytest.importorskip("matplotlib")
    import numpy as np
    from matplotlib.colors import to_hex

    from aou_dsl.media.plot import ProfileData, profile_figure

    _install(monkeypatch, SimpleNamespace(colour="#123abc", label="anticipation"))
    t = np.linspace(0.0, 3.0, 31)
    z = np.zeros((31, 1))
    data = ProfileData("t", ("j1",), t, np.sin(t) ** 2, np.full(31, 0.3), z, z,
                       np.array([-1.0]), np.array([1.0]), np.array([1.0]),
                       ((APPROACH, 0.0, 1.0), (KIND, 1.0, 2.0), ("unknown", 2.0, 3.0)))
    fig = profile_figure(data)
    ax = fig.axes[0]
    spans = [to_hex(p.get_facecolor()) for p in ax.patches]
    assert spans[:3] == [kind_labels.BUILTIN[APPROACH].colour, "#123abc",
                         kind_labels.DEFAULT_COLOUR]
    assert [x.get_text() for x in ax.texts][:3] == [APPROACH, "anticipation", "unknown"]
