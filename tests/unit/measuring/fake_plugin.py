"""A plugin kind for the measuring tests, defined here (not installed): a counter-
movement away from the goal directly before an approach, which the built-in recognisers
read as a retreat followed, with no pause between, by an approach.

:func:`install` puts it where the measuring registry looks for plugins, and only there:
the rest of aou does not see it."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

from aou_dsl.core.plugins import Plugin
from aou_dsl.lang.descriptors import REGISTRY, Aggregate, Descriptor
from aou_dsl.lang.primitives import APPROACH, RETREAT
from aou_dsl.measuring import recognisers

#: A retreat of 1 cm straight into an approach (the counter-movement), then a retreat of
#: 2 cm between two pauses (a retreat as the descriptors count it).
COUNTER = """behaviour counter
robot panda
start 0.30m
standoff 0.10m

sequence {
  approach 0.05m a=0.1
  pause 1s
  retreat 0.01m a=0.1
  approach 0.07m a=0.1
  pause 1s
  retreat 0.02m a=0.1
  pause 1s
}
"""

KIND = "anticipate"
SOURCE = "aou-fake 0.1"
DISTANCE = Descriptor(f"{KIND}_distance", "m", KIND, "distance", Aggregate.MEDIAN,
                      "length", abs_tol=1e-3)
COUNT = Descriptor(f"{KIND}_count", "", KIND, "", Aggregate.COUNT, "count")


class Claim:
    """The plugin's measure pass: a retreat directly followed by an approach is its."""

    def claim(self, episodes):
        out = list(episodes)
        for i, e in enumerate(out[:-1]):
            if e.kind == RETREAT and out[i + 1].kind == APPROACH:
                out[i] = replace(e, kind=KIND)
        return out


def install(monkeypatch, *, measure=None, descriptors=(DISTANCE, COUNT)) -> Plugin:
    """Make the fake plugin the one loaded plugin, as the measuring registry sees it;
    ``measure`` its measure part (None: it gives none)."""
    parts = {"kind": object(), "descriptors": tuple(descriptors)}
    if measure is not None:
        parts["measure"] = measure
    plugin = Plugin(KIND, SOURCE, parts)
    monkeypatch.setattr(recognisers, "_plugins", SimpleNamespace(plugins=lambda: (plugin,)))
    every = {d.name: d for d in (*REGISTRY.values(), *descriptors)}
    monkeypatch.setattr(recognisers, "_descriptors", SimpleNamespace(
        every_descriptor=lambda: every))
    return plugin


def no_plugins(monkeypatch) -> None:
    """No plugin loaded, whatever is installed."""
    monkeypatch.setattr(recognisers, "_plugins", SimpleNamespace(plugins=lambda: ()))
    monkeypatch.setattr(recognisers, "_descriptors", SimpleNamespace(
        every_descriptor=lambda: dict(REGISTRY)))
