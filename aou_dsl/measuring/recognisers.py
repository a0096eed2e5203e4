"""How each kind's episode is recognised in a measured motion, and its values read back:
the measurement's registry, keyed by kind.

The built-in kinds are recognised by what moved between two boundaries of
:mod:`.holds` (:data:`BUILTIN`):

- a hold (every joint still): a pause, its ``duration``;
- a move along the line of sight (:func:`.episodes.translation`): an approach when it
  ends closer to the goal, a retreat when further, with its ``distance`` and
  ``peak_acceleration``;
- a move around the goal: a gaze, its ``horizontal`` and ``vertical`` bearings;
- a turn in place (:mod:`.roll`): a shiver (a fast oscillation, its ``amplitude`` and
  ``frequency``) or a tilt (one roll, its ``angle`` and ``velocity``).

A plugin kind (an ``aou.kinds`` entry point, :mod:`aou_dsl.core.plugins`) is measured
by its ``measure`` part, a :class:`MeasurePart`: a pass over the episodes the built-ins
found that claims the plugin's own (relabels them, or merges several into one) and
gives their values. The passes run after the built-ins, in the plugins' order. Its
descriptors (its ``descriptors`` part) are then aggregated from the episodes of its kind
exactly as the eleven are (counts, medians, maxima over the episodes that count) and
reported after the eleven.

A plugin whose ``measure`` part has no ``claim`` is treated as giving none, and a pass
that raises or returns something else than episodes is left out with a K801 warning
(:func:`claimed`); a file that declares a kind whose plugin gives no usable ``measure``
part cannot be judged against a recording (K802, :func:`missing_part`): its episodes
would be read as built-in ones, and every verdict on them would be wrong.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from ..core import plugins as _plugins
from ..core.codes import K801, K802
from ..core.diagnostics import Diagnostic, Span, diag
from ..lang import descriptors as _descriptors
from ..lang.descriptors import REGISTRY, Aggregate, Descriptor, EpisodeValues, qualify
from ..lang.primitives import APPROACH, GAZE, PAUSE, RETREAT, SHIVER, TILT

__all__ = ["BUILTIN", "LAYER", "MeasurePart", "Recogniser", "aggregate", "claimed",
           "every_named", "extra_descriptors", "extra_values", "missing_part", "moved_along",
           "recognisers"]

#: The layer name under which a plugin gives its part (:data:`aou_dsl.core.plugins.LAYERS`).
LAYER = "measure"


@runtime_checkable
class MeasurePart(Protocol):
    """What a plugin's ``measure`` part must give.

    ``claim(episodes)`` receives the measured episodes in time order (built-in kinds,
    and those earlier plugins claimed), each an
    :class:`~aou_dsl.lang.descriptors.EpisodeValues` with its kind, its times [s] from
    the recording's first sample and its values (a retreat's ``distance`` [m] and
    ``peak_acceleration`` [m/s^2], a pause's ``duration`` [s], ...). It returns the
    episodes with its kind's own claimed: the same list, with some replaced by
    ``EpisodeValues(<its kind>, t_start, t_end, {<its value keys>: ...})``. It must
    return every episode it does not claim unchanged and in order; it must not raise
    for a motion without its episodes (it returns the list as it got it).

    Its values' keys are the ``key`` of its descriptors (its ``descriptors`` part,
    :class:`~aou_dsl.lang.descriptors.Descriptor` records with ``kind`` its keyword).

    Example: a counter-movement before an approach is measured as a retreat directly
    followed (no pause between them) by an approach; its pass relabels that retreat as
    its kind, keeping its ``distance`` and ``peak_acceleration``.
    """

    def claim(self, episodes: Sequence[EpisodeValues]) -> Sequence[EpisodeValues]: ...


@dataclass(frozen=True, slots=True)
class Recogniser:
    """How one kind is recognised: ``kind`` its keyword, ``source`` who gives it (``aou``
    or the plugin's distribution), ``reads`` the motion it is read from, ``keys`` the
    values its episodes carry (a plugin's: its descriptors' keys), ``part`` a plugin's
    :class:`MeasurePart` (None for a built-in)."""

    kind: str
    source: str
    reads: str
    keys: tuple[str, ...]
    part: MeasurePart | None = None


#: The built-in kinds' recognisers, in :data:`aou_dsl.lang.descriptors.REGISTRY`'s order
#: of kinds.
BUILTIN: dict[str, Recogniser] = {r.kind: r for r in (
    Recogniser(APPROACH, "aou", "a move along the line of sight, ending closer to the goal",
               ("distance", "peak_acceleration", "peak_acceleration_sd")),
    Recogniser(PAUSE, "aou", "a hold: every joint still within its noise", ("duration",)),
    Recogniser(RETREAT, "aou", "a move along the line of sight, ending further from the goal",
               ("distance", "peak_acceleration", "peak_acceleration_sd")),
    Recogniser(GAZE, "aou", "a move around the goal", ("horizontal", "vertical", "angle")),
    Recogniser(TILT, "aou", "one roll in place", ("angle", "signed", "velocity", "joint")),
    Recogniser(SHIVER, "aou", "a fast oscillation in place",
               ("amplitude", "joint", "cycles", "frequency")),
)}


def moved_along(closer: bool) -> str:
    """The kind of a move along the line of sight: an approach when it ends closer to the
    goal, else a retreat."""
    return APPROACH if closer else RETREAT


def _usable(part: object) -> bool:
    return part is not None and callable(getattr(part, "claim", None))


def recognisers() -> dict[str, Recogniser]:
    """Every kind measuring recognises: the built-ins, then each loaded plugin kind with a
    usable ``measure`` part (a built-in's keyword is never taken over)."""
    out = dict(BUILTIN)
    for p in _plugins.plugins():
        part = p.part(LAYER)
        if p.name in out or not _usable(part):
            continue
        keys = tuple(d.key for d in extra_descriptors() if d.kind == p.name and d.key)
        out[p.name] = Recogniser(p.name, p.source, "its plugin's pass over the episodes",
                                 keys, part)  # type: ignore[arg-type]
    return out


def claimed(episodes: Sequence[EpisodeValues], where: Span | None = None
            ) -> tuple[list[EpisodeValues], list[Diagnostic]]:
    """``episodes`` after each plugin's pass, and a K801 warning for each pass that
    could not be used (it raised, or returned something not a list of episodes in time
    order): its claims are left out, the episodes as they were before it."""
    out = list(episodes)
    diags: list[Diagnostic] = []
    for r in recognisers().values():
        if r.part is None:
            continue
        why: str | None
        try:
            got: list[object] = list(r.part.claim(tuple(out)))
        except Exception as exc:  # a plugin may fail in any way: say so, go on without it
            why = f"its measure pass raised {type(exc).__name__}: {exc}"
        else:
            why = _malformed(got)
            if why is None:
                out = [e for e in got if isinstance(e, EpisodeValues)]
                continue
        diags.append(diag(K801, f"the plugin kind `{r.kind}` ({r.source}) is not measured: "
                          f"{why}", where or Span.whole_file("<measure>"), kind=r.kind,
                          plugin=r.source, stage=LAYER))
    return out, diags


def _malformed(got: list[object]) -> str | None:
    """Why what a pass returned is not a list of episodes in time order (None: it is)."""
    last = float("-inf")
    for e in got:
        if not isinstance(e, EpisodeValues) or not isinstance(e.kind, str):
            return f"it returned {type(e).__name__}, not an episode"
        if not all(isinstance(v, int | float) for v in e.values.values()):
            return f"an episode of `{e.kind}` has a value that is not a number"
        if e.t_start < last - 1e-9 or e.t_end < e.t_start:
            return f"its episodes are not in time order (at t={e.t_start:.3f}s)"
        last = e.t_start
    return None


def extra_descriptors() -> tuple[Descriptor, ...]:
    """The plugins' descriptors, after the eleven of
    :data:`~aou_dsl.lang.descriptors.REGISTRY` (the registry's ``every_descriptor``, which
    has already left out the malformed and the taken)."""
    return tuple(d for name, d in _descriptors.every_descriptor().items()
                 if name not in REGISTRY)


def every_named() -> Mapping[str, Descriptor]:
    """The eleven then the plugins' descriptors, by name, in the order they are
    reported."""
    return _descriptors.every_descriptor()


def aggregate(d: Descriptor, episodes: Sequence[EpisodeValues]) -> float | int | None:
    """Descriptor ``d`` of already qualified ``episodes``: the number of its kind's
    episodes that count, or the median or maximum of their ``d.key`` values (None when
    none carries it), as the eleven are derived."""
    mine = [e for e in episodes if e.kind == d.kind and e.counts]
    if d.is_count:
        return len(mine)
    values = sorted(float(e.values[d.key]) for e in mine if d.key in e.values)
    if not values:
        return None
    if d.aggregate is Aggregate.MAX:
        return values[-1]
    mid = len(values) // 2
    return values[mid] if len(values) % 2 else (values[mid - 1] + values[mid]) / 2


def extra_values(episodes: Iterable[EpisodeValues]) -> dict[str, float | int | None]:
    """The plugins' descriptors of ``episodes`` (in time order), by name, in
    :func:`extra_descriptors`' order; empty without plugins."""
    extra = extra_descriptors()
    if not extra:
        return {}
    eps = qualify(episodes)
    return {d.name: aggregate(d, eps) for d in extra}


def missing_part(kinds: Iterable[str], where: Mapping[str, Span]) -> list[Diagnostic]:
    """K802 for each plugin kind in ``kinds`` (a file's) whose plugin gives no usable
    ``measure`` part, at ``where[kind]`` (the statement that uses it)."""
    known = recognisers()
    out = []
    for p in _plugins.plugins():
        if p.name not in kinds or p.name in known:
            continue
        given = p.part(LAYER)
        why = ("gives no measure part" if given is None else
               f"gives a measure part ({type(given).__name__}) without a claim(episodes) "
               "method")
        out.append(diag(K802, f"the kind `{p.name}` comes from the plugin {p.source}, which "
                        f"{why}: a recording cannot be judged against a file that uses it "
                        "(its episodes would be read as other kinds)",
                        where.get(p.name) or Span.whole_file("<measure>"),
                        kind=p.name, plugin=p.source, stage=LAYER))
    return out
