"""A synthesized behaviour under construction: descriptor-form statements, one per slot.

A :class:`Recipe` holds the primitive nodes of a descriptor-form behaviour (a count of 0
is an absent primitive) and, per descriptor or parameter, a note saying where its value
came from. Descriptors are read and written through ``REGISTRY`` (kind, episode key, IR
field and scale), as ``aouc variants`` does. Pure Python.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from ..fit.rounding import significant
from ..lang.descriptors import Descriptor, every_descriptor
from ..lang.ir import State
from ..lang.primitives import KINDS, PAUSE
from .kind_recipes import descriptors, kind_recipes, pauses_needed, slots

__all__ = ["Recipe", "descriptor", "slot_of"]

#: A statement of a descriptor-form file: its kind and its plane (None for a kind
#: without planes); the registry (:func:`.kind_recipes.slots`) gives them in order.
Slot = tuple[str, str | None]


def descriptor(kind: str, key: str) -> Descriptor:
    """The descriptor read from episodes of ``kind`` by ``key`` ("" for the count)."""
    for d in every_descriptor().values():
        if d.kind == kind and (d.key == key or (d.is_count and key == "")):
            return d
    raise KeyError((kind, key))


def slot_of(d: Descriptor) -> Slot:
    """The statement that sets descriptor ``d``."""
    r = kind_recipes().get(d.kind)
    return d.kind, (d.key if r is not None and r.planes != (None,) else None)


@dataclass(frozen=True)
class Recipe:
    """Primitive nodes by slot (``count`` 0: absent) and notes by descriptor name."""

    nodes: Mapping[Slot, Any]
    notes: Mapping[str, str] = field(default_factory=dict)

    @classmethod
    def of(cls, primitives: Iterable[Any]) -> Recipe:
        return cls({(p.kind, getattr(p, "plane", None)): p for p in primitives})

    def node(self, kind: str, plane: str | None = None) -> Any:
        return self.nodes.get((kind, plane))

    def count(self, kind: str, plane: str | None = None) -> int:
        node = self.node(kind, plane)
        return node.count if node is not None else 0

    def present(self, d: Descriptor) -> bool:
        return self.count(*slot_of(d)) > 0

    def value(self, d: Descriptor) -> float:
        """The descriptor's value in its unit; 0 when its primitive is absent."""
        node = self.nodes.get(slot_of(d))
        if node is None or node.count == 0:
            return 0
        if d.is_count:
            return node.count
        return KINDS[d.kind].values(node)[d.key]

    def with_node(self, node: Any) -> Recipe:
        key = (node.kind, getattr(node, "plane", None))
        return replace(self, nodes={**self.nodes, key: node})

    def noted(self, name: str, note: str) -> Recipe:
        return replace(self, notes={**self.notes, name: note})

    def with_value(self, d: Descriptor, value: float, note: str | None = None,
                   count: int | None = None) -> Recipe:
        """The recipe with ``d`` set to ``value`` (in its unit); ``count`` also sets how
        many episodes its statement makes."""
        node = self.nodes[slot_of(d)]
        update: dict[str, Any] = {d.ir_field: int(value) if d.is_count else value * d.scale}
        if count is not None:
            update["count"] = count
        out = self.with_node(node.replace(**update))
        return out.noted(d.name, note) if note is not None else out

    @classmethod
    def blend(cls, recipes: Mapping[State, Recipe], w: Mapping[State, float]) -> Recipe:
        """The weighted blend of several states' recipes: per statement, the count is the
        rounded weighted mean (absent counts 0); each value the weighted mean over the
        states that have the statement; other parameters are the heaviest state's."""
        nodes: dict[Slot, Any] = {}
        every = descriptors()
        for slot in slots():
            having = {s: r for s, r in recipes.items() if r.count(*slot) > 0}
            n = math.floor(sum(w[s] * r.count(*slot) for s, r in having.items()) + 0.5)
            if not having or n < 1:
                continue
            top = max(having, key=lambda s: w[s])
            node = having[top].nodes[slot].replace(count=n)
            total = sum(w[s] for s in having)
            for d in every:
                if slot_of(d) == slot and not d.is_count:
                    v = sum(w[s] * r.value(d) for s, r in having.items()) / total
                    node = node.replace(
                        **{d.ir_field: significant(v, 3, "nearest") * d.scale})
            nodes[slot] = node
        out = cls(nodes)
        need = pauses_needed(out.count)
        pause = next(r.node(PAUSE) for r in recipes.values() if r.count(PAUSE))
        if out.count(PAUSE) < need:  # a retreat starts and ends at a pause
            out = out.with_node((out.node(PAUSE) or pause).replace(count=need))
        shown = ", ".join(f"{s} {x:.2f}" for s, x in sorted(w.items(), key=lambda i: -i[1]))
        for d in every:
            if out.present(d):
                how = "rounded weighted mean" if d.is_count else "weighted mean"
                out = out.noted(d.name, f"{how} of the blend of {shown}")
        return out
