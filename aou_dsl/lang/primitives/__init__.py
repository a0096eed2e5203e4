"""The primitive kinds of the language, one module each, and their registry.

A new built-in kind is one new module (a :class:`~.kind.Kind` subclass and its IR node)
and one line in :data:`BUILTIN_KINDS`. A kind from another package is a plugin (the
``aou.kinds`` entry point group, :mod:`aou_dsl.core.plugins`) whose ``kind`` part is an
instance of a :class:`~.kind.Kind` subclass named as its entry point; :data:`KINDS` holds
both, and :func:`plugin_problems` says why a plugin's kind is not among them (K801:
it did not load or its part is not a kind; K803: its keyword is taken).
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from ...core import plugins as _plugins
from ...core.codes import K801, K803
from ...core.memo import table
from ..evidence import evidence_problem
from .approach import Approach, ApproachKind
from .gaze import GAZE_ANGULAR_ACCEL, Gaze, GazeKind
from .kind import LOOK_SLACK, MIN_ANGLE, MIN_PAUSE, MIN_RETREAT, Kind, Timing
from .pause import Pause, PauseKind
from .retreat import Retreat, RetreatKind
from .shiver import LOOK_SHIVER_F, MIN_SHIVER_F, VISIBLE_SHIVER, Shiver, ShiverKind, shiver_duration
from .tilt import Tilt, TiltKind

__all__ = [
    "APPROACH",
    "BUILTIN_KINDS",
    "GAZE",
    "GAZE_ANGULAR_ACCEL",
    "KINDS",
    "LOOK_SHIVER_F",
    "LOOK_SLACK",
    "MIN_ANGLE",
    "MIN_PAUSE",
    "MIN_RETREAT",
    "MIN_SHIVER_F",
    "PAUSE",
    "RETREAT",
    "SHIVER",
    "TILT",
    "Approach",
    "Gaze",
    "Kind",
    "Timing",
    "Pause",
    "Retreat",
    "Shiver",
    "Tilt",
    "VISIBLE_SHIVER",
    "PluginProblem",
    "is_builtin",
    "kind_of",
    "look_changed",
    "plugin_problems",
    "shiver_duration",
]

#: The built-in kinds' keywords as the kinds themselves spell them. Every other module
#: names a kind through these (or a kind object's ``name``), never by a string literal:
#: ``tests/unit/test_kind_names.py`` fails on one.
APPROACH, PAUSE, RETREAT, GAZE, TILT, SHIVER = (
    ApproachKind.name, PauseKind.name, RetreatKind.name, GazeKind.name, TiltKind.name,
    ShiverKind.name)

#: The kinds aou itself has, by statement keyword.
BUILTIN_KINDS: Mapping[str, Kind] = MappingProxyType({k.name: k for k in (
    ApproachKind(), PauseKind(), RetreatKind(), GazeKind(), TiltKind(), ShiverKind(),
)})

#: What a plugin kind's keyword must look like: a word of the language.
_WORD = re.compile(r"[a-z][a-z0-9_]*\Z")


@dataclass(frozen=True, slots=True)
class PluginProblem:
    """Why a plugin's kind (or one of its parts) is not used: ``code`` is K801 (it did
    not load, or what it gives is malformed) or K803 (its name is taken)."""

    code: str
    name: str
    source: str
    why: str

    def message(self) -> str:
        return f"plugin `{self.name}` ({self.source}): {self.why}"


def _problem_of_kind(p: _plugins.Plugin, taken: Mapping[str, object]) -> PluginProblem | None:
    kind = p.part("kind")
    if not isinstance(kind, Kind):
        return PluginProblem(K801, p.name, p.source, "its `kind` part is not an instance of "
                             f"aou's Kind (it is a {type(kind).__name__})")
    if getattr(kind, "name", None) != p.name:
        return PluginProblem(K801, p.name, p.source, f"its kind is named "
                             f"`{getattr(kind, 'name', None)}`, its entry point `{p.name}`")
    if not _WORD.match(p.name):
        return PluginProblem(K801, p.name, p.source,
                             "its keyword is not a lower-case word of the language")
    why = evidence_problem(getattr(kind, "evidence", None))
    if why is None and not isinstance(getattr(kind, "timing", None), Timing):
        why = "its `timing` is not one of aou's Timing"
    if why is not None:
        return PluginProblem(K801, p.name, p.source, why)
    if p.name in taken:
        who = "a built-in kind" if p.name in BUILTIN_KINDS else "an earlier plugin"
        return PluginProblem(K803, p.name, p.source,
                             f"its keyword is already {who}'s, which keeps it")
    return None


#: The last table made, with the :func:`~aou_dsl.core.plugins.loaded` result it was made
#: from (kept alive here, so an identity check cannot be fooled by a reused id).
_KEPT = table("aou_dsl.lang.primitives.kinds", 1)


def _table() -> tuple[Mapping[str, Kind], tuple[PluginProblem, ...]]:
    """Every kind by keyword and the plugin problems, made again when the loaded plugins
    change (:func:`aou_dsl.core.plugins.loaded` returns another object)."""
    got = _plugins.loaded()
    kept = _KEPT.get("kinds")
    if kept is not None and kept[0] is got:
        return kept[1], kept[2]
    good, broken = got
    table: dict[str, Kind] = dict(BUILTIN_KINDS)
    problems = [PluginProblem(K801, b.name, b.source, b.why) for b in broken]
    for p in good:
        why = _problem_of_kind(p, table)
        if why is not None:
            problems.append(why)
            continue
        table[p.name] = p.part("kind")  # type: ignore[assignment]
    out = (MappingProxyType(table), tuple(problems))
    _KEPT.put("kinds", (got, *out))
    return out


def plugin_problems() -> tuple[PluginProblem, ...]:
    """Why installed plugins' kinds are not used (K801, K803), in load order."""
    return _table()[1]


class _Kinds(Mapping[str, Kind]):
    """Every primitive kind by statement keyword: the built-ins, then the kinds of the
    plugins loaded now (a live view: it follows :func:`aou_dsl.core.plugins.loaded`)."""

    __slots__ = ()

    def __getitem__(self, name: str) -> Kind:
        return _table()[0][name]

    def __iter__(self) -> Iterator[str]:
        return iter(_table()[0])

    def __len__(self) -> int:
        return len(_table()[0])

    def __contains__(self, name: object) -> bool:
        return name in _table()[0]

    def __repr__(self) -> str:
        return f"KINDS({', '.join(self)})"


#: Every primitive kind, by statement keyword: :data:`BUILTIN_KINDS` and the plugins'.
KINDS: Mapping[str, Kind] = _Kinds()


def is_builtin(name: str) -> bool:
    """Whether ``name`` is one of aou's own kinds (not a plugin's)."""
    return name in BUILTIN_KINDS


def look_changed(declared, fitted) -> str | None:
    """Why the episodes ``fitted`` (a fitted file's timeline) do not look like
    ``declared`` (the file's as written), episode by episode by each kind's own
    invariant (:meth:`Kind.keeps_look`), or None when every one keeps its look."""
    if len(declared) != len(fitted):
        return f"it would have {len(fitted)} episodes, not {len(declared)}"
    for d, f in zip(declared, fitted, strict=True):
        why = KINDS[d.kind].keeps_look(d, f)
        if why is not None:
            return why
    return None


def kind_of(node) -> Kind:
    """The kind object of an IR node (or of an episode's ``kind``)."""
    return KINDS[node if isinstance(node, str) else node.kind]
