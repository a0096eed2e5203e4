"""A fake primitive kind plugin for the registries' unit tests: ``lunge``, a retreat under
another keyword, with the parts a test gives it.

It is "loaded" by replacing :func:`aou_dsl.core.plugins.loaded` (which ``plugins()``,
``part()`` and the kind table follow). While the kind table is still a plain dict of the
built-ins, the kind is also added to it; while the descriptor table has no
``every_descriptor``, one is set up as its contract says: the registry's descriptors,
then each loaded plugin's ``descriptors`` part.
"""

from __future__ import annotations

from typing import Any

from aou_dsl.core import plugins
from aou_dsl.lang import descriptors as table
from aou_dsl.lang import primitives
from aou_dsl.lang.descriptors import Aggregate, Descriptor
from aou_dsl.lang.ir import State
from aou_dsl.lang.primitives.retreat import RetreatKind

NAME = "lunge"
SOURCE = "aou-lunge 0.1"


class LungeKind(RetreatKind):
    name = NAME
    usage = "lunge DIST [a=ACC] [v=SPEED] [xN]"


#: Its descriptors (the plugin's ``descriptors`` part).
DESCRIPTORS = (
    Descriptor("lunge_distance", "m", NAME, "distance", Aggregate.MEDIAN, "length",
               abs_tol=1e-3, stronger={State.HESITANT: +1}),
    Descriptor("lunge_count", "", NAME, "", Aggregate.COUNT, "count"),
    Descriptor("lunge_acceleration", "m/s^2", NAME, "peak_acceleration", Aggregate.MAX, "a",
               rel_tol=0.03),
)


def _every() -> dict[str, Descriptor]:
    out = dict(table.REGISTRY)
    for p in plugins.plugins():
        out.update((d.name, d) for d in p.part("descriptors") or ())  # type: ignore[attr-defined]
    return out


def install(monkeypatch: Any, **parts: object) -> plugins.Plugin:
    """Load the plugin ``lunge`` with its kind and descriptors and the given parts (a
    part given as None is left out)."""
    given = {"kind": LungeKind(), "descriptors": DESCRIPTORS, **parts}
    plugin = plugins.Plugin(NAME, SOURCE, {k: v for k, v in given.items() if v is not None})
    got: tuple[tuple[plugins.Plugin, ...], tuple[plugins.Broken, ...]] = ((plugin,), ())
    monkeypatch.setattr(plugins, "loaded", lambda: got)
    if NAME not in primitives.KINDS:  # the table does not follow the plugins yet
        monkeypatch.setitem(primitives.KINDS, NAME, given["kind"])
    if not hasattr(table, "every_descriptor"):
        monkeypatch.setattr(table, "every_descriptor", _every, raising=False)
    return plugin
