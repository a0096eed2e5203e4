"""The test plugin ``aou-anticipate`` in each layer's registry, in this process: every
part it gives is taken where the layer reads it, the editor completes the kind, the
studio gives its distance a slider, and uninstalled, none of it is there."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from aou_dsl.lang.descriptors import EpisodeValues
from tests.plugins.install import installed, wind_up

SEQUENCE = wind_up("12mm", 0.3, 0.05)


@pytest.fixture
def plugin(tmp_path):
    """The plugin installed, and its object (as the entry point gives it)."""
    with installed(tmp_path):
        import aou_anticipate

        yield aou_anticipate.plugin


def _layers() -> dict[str, object]:
    """What each layer's registry holds for the kind (None: nothing)."""
    from aou_dsl.dmp.parts import dmp_kinds
    from aou_dsl.editor.kind_texts import kind_texts
    from aou_dsl.lang.descriptors import every_descriptor
    from aou_dsl.lang.primitives import KINDS
    from aou_dsl.measuring.recognisers import recognisers
    from aou_dsl.media.kind_labels import labels
    from aou_dsl.studio.kind_controls import kind_controls
    from aou_dsl.synth.kind_recipes import kind_recipes

    every = every_descriptor()
    names = list(every) if isinstance(every, dict) else [d.name for d in every]
    return {"kind": KINDS.get("anticipate"),
            "descriptors": [n for n in names if n.startswith("anticipate_")] or None,
            "measure": recognisers().get("anticipate"),
            "dmp": dmp_kinds().get("anticipate"),
            "synth": kind_recipes().get("anticipate"),
            "editor": kind_texts().get("anticipate"),
            "studio": kind_controls().get("anticipate"),
            "media": labels().get("anticipate")}


def test_every_layer_takes_the_part_the_plugin_gives(plugin):
    from aou_dsl.core.units import Dim
    from aou_dsl.dmp.parts import Shape

    got = _layers()
    assert got["kind"] is plugin.kind
    assert got["descriptors"] == ["anticipate_count", "anticipate_distance"]
    assert got["measure"].part is plugin.measure
    assert got["dmp"].shape is Shape.MOVE
    assert got["editor"].positional is Dim.LENGTH
    assert got["editor"].definitions["anticipate_distance"].startswith("distance")
    assert got["studio"].colour == (212, 160, 23)
    assert got["media"].colour == "#d4a017" and got["media"].label == "anticipation"
    assert got["synth"] is None  # it gives no synthesis recipe: synthesis leaves it out


def test_uninstalled_no_layer_knows_the_kind():
    assert set(_layers().values()) == {None}


# --- measurement: the plugin's pass ---------------------------------------------------------


def _ev(kind: str, t0: float, t1: float, **values: float) -> EpisodeValues:
    return EpisodeValues(kind, t0, t1, values)


@pytest.mark.parametrize(("episodes", "kinds"), [
    # a short move away an approach follows at once: an anticipation
    ([_ev("pause", 0, 1, duration=1), _ev("retreat", 1, 1.4, distance=0.01),
      _ev("approach", 1.4, 3)], ["pause", "anticipate", "approach"]),
    # a pause between them: a retreat, as before
    ([_ev("retreat", 0, 0.4, distance=0.01), _ev("pause", 0.4, 1, duration=0.6),
      _ev("approach", 1, 3)], ["retreat", "pause", "approach"]),
    # larger than an anticipation: a retreat
    ([_ev("retreat", 0, 0.4, distance=0.08), _ev("approach", 0.4, 3)],
     ["retreat", "approach"]),
    # a move away at the end: nothing follows it
    ([_ev("approach", 0, 2), _ev("retreat", 2, 2.4, distance=0.01)],
     ["approach", "retreat"]),
])
def test_the_measure_pass_claims_only_a_draw_back_before_an_approach(plugin, episodes,
                                                                        kinds):
    out = list(plugin.measure.claim(tuple(episodes)))
    assert [e.kind for e in out] == kinds
    for before, after in zip(episodes, out, strict=True):
        assert (before.t_start, before.t_end, dict(before.values)) == \
            (after.t_start, after.t_end, dict(after.values))


# --- the editor -----------------------------------------------------------------------------


def _doc(text: str):
    from aou_dsl.editor.convert import Text
    from aou_dsl.editor.state import Document

    return Document(uri="file:///w.aou", path="/w.aou", view=Text(text))


def _labels(text: str, line: int, col: int) -> list[str]:
    from lsprotocol import types

    from aou_dsl.editor.completion import complete

    got = complete(_doc(text), types.Position(line=line, character=col))
    return [i.label for i in got.items]


def test_the_editor_completes_the_kind_its_key_and_its_units(plugin):
    pytest.importorskip("lsprotocol")
    lines = SEQUENCE.splitlines()
    at = lines.index("  anticipate 12mm a=0.3")
    assert "anticipate" in _labels(SEQUENCE, at, 2)  # a statement's first word
    typed = SEQUENCE.replace("  anticipate 12mm a=0.3", "  anticipate 12")
    units = _labels(typed, at, len("  anticipate 12"))
    assert units and set(units) == {"12m", "12cm", "12mm"}, units  # lengths only
    keyed = SEQUENCE.replace("  anticipate 12mm a=0.3", "  anticipate 12mm ")
    assert "a=" in _labels(keyed, at, len("  anticipate 12mm "))


def test_uninstalled_the_editor_does_not_offer_it():
    pytest.importorskip("lsprotocol")
    at = SEQUENCE.splitlines().index("  anticipate 12mm a=0.3")
    assert "anticipate" not in _labels(SEQUENCE, at, 2)


# --- the studio -----------------------------------------------------------------------------


class _Gui:
    """The part of the studio's GUI server the sliders use, recording the sliders made."""

    def __init__(self) -> None:
        self.sliders: dict[str, tuple] = {}

    def add_folder(self, name: str):
        import contextlib

        return contextlib.nullcontext()

    def add_slider(self, name, lo, hi, step, value, hint=""):
        self.sliders[name] = (lo, hi, step, value)
        return SimpleNamespace(min=lo, max=hi, value=value, on_update=lambda f: None,
                               remove=lambda: None)


def test_the_studio_gives_its_distance_a_slider(plugin):
    """The studio reads the file the way it shows it: what the file sets, then one slider
    each, over the range the plugin gives (its kind's 5 to 50 mm)."""
    from aou_dsl.api import lint_source
    from aou_dsl.studio.controls import Sliders
    from aou_dsl.studio.edits import settable

    lint = lint_source(SEQUENCE, "w.aou")
    assert lint.behaviour is not None, [d.message for d in lint.diagnostics]
    values = settable(lint.behaviour, lint.timeline)
    assert values.get("anticipate_distance") == pytest.approx(0.012)
    gui = _Gui()
    Sliders(SimpleNamespace(gui=gui), lambda v: None).show(values)
    lo, hi, step, value = gui.sliders["anticipate_distance"]
    assert (lo, hi, step) == pytest.approx((0.005, 0.05, 0.001))
    assert value == pytest.approx(0.012)


def test_the_editor_hovers_the_kind_with_the_plugins_texts(plugin):
    """Hover over the keyword shows its usage and its laid-out episodes (two, of the
    kind); over its distance, the plugin's own definition of the descriptor it sets."""
    pytest.importorskip("lsprotocol")
    from aou_anticipate.descriptors import DEFINITIONS
    from lsprotocol import types

    from aou_dsl.api import lint_source
    from aou_dsl.editor.hover import hover

    src = ("behaviour w : confident\nrobot panda\nstart 0.35m\nstandoff 0.10m\n"
           "approach a=0.1\nanticipate 12mm a=0.3 x2\npause 1s x2\n")
    doc = _doc(src)
    doc.lint = lint_source(src, doc.path)

    def text(col: int) -> str:
        got = hover(doc, types.Position(line=5, character=col))
        return got.contents.value if got is not None else ""

    keyword = text(2)
    assert plugin.kind.usage in keyword and keyword.count("- anticipate at") == 2, keyword
    distance = text(len("anticipate 1"))
    assert DEFINITIONS["anticipate_distance"] in distance
    # The study varied the eleven only: hover claims no finding about a plugin's.
    assert "study found" not in distance and "no perceived effect is known" in distance
