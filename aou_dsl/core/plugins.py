"""Primitive kinds that other packages add: the ``aou.kinds`` entry point group.

A plugin is an installed distribution that names, in its metadata, an object under the
entry point group :data:`GROUP`, the way pytest and flake8 find theirs. The entry point's
name is the kind's keyword. The object it points at gives one part per layer it takes
part in, as attributes named in :data:`LAYERS` (a module or any object will do); each
layer reads its own part, checks it, and says with a diagnostic (K802) when a file uses
the kind for something the plugin gives nothing for. Nothing here imports a name read
from a file: the names come from the installed packages' own metadata, which is the
environment the user chose, like a ``pip install``.

``AOU_NO_PLUGINS=1`` in the environment loads none (a clean run, as without them).
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from .memo import cached

if TYPE_CHECKING:
    from importlib import metadata

__all__ = ["GROUP", "LAYERS", "Broken", "Plugin", "loaded", "part", "plugins"]

#: The entry point group aou reads.
GROUP = "aou.kinds"
#: The parts a plugin may give, by the layer that reads each: ``kind`` (the syntax piece,
#: its validation, its C-V evidence and its time law: a ``lang.primitives.kind.Kind``),
#: ``measure`` (how to recognise its episode in a motion and read its values back),
#: ``dmp`` (its part of a DMP folder), ``synth`` (its synthesis recipe), ``editor`` (its
#: completion and hover texts), ``studio`` (its slider and colour), ``media`` (its label
#: and colour in plots), ``descriptors`` (the descriptors it adds).
LAYERS = ("kind", "measure", "dmp", "synth", "editor", "studio", "media", "descriptors")


@dataclass(frozen=True, slots=True)
class Plugin:
    """One loaded plugin: the kind's keyword, the distribution that gave it and the
    parts it gives, by layer."""

    name: str
    source: str
    parts: Mapping[str, object] = field(default_factory=dict)

    def part(self, layer: str) -> object | None:
        return self.parts.get(layer)


@dataclass(frozen=True, slots=True)
class Broken:
    """An entry point that could not be used, and why (reported as K801)."""

    name: str
    source: str
    why: str


def _source(ep: metadata.EntryPoint) -> str:
    dist = ep.dist
    return f"{dist.name} {dist.version}" if dist is not None else ep.value


def loaded() -> tuple[tuple[Plugin, ...], tuple[Broken, ...]]:
    """Every plugin of :data:`GROUP` that loads, in the order of their names, and the
    entry points that do not. Kept by what it depends on: ``AOU_NO_PLUGINS`` and the
    import path (where installed distributions are found); ``loaded.cache_clear()``
    forgets it (after installing a package in the same process)."""
    off = os.environ.get("AOU_NO_PLUGINS", "") not in ("", "0")
    return _load(off, tuple(sys.path))


#: A section header of :data:`GROUP` in an ``entry_points.txt``.
_SECTION = re.compile(r"^\s*\[\s*" + re.escape(GROUP) + r"\s*\]", re.MULTILINE)


def _declared(path: tuple[str, ...]) -> bool:
    """Whether a distribution on ``path`` may declare an entry point of :data:`GROUP`:
    its ``*.dist-info`` or ``*.egg-info`` folder's ``entry_points.txt`` has the section.
    A few milliseconds, where importing :mod:`importlib.metadata` (email, zipfile, csv)
    and reading every distribution costs tens: ``aouc lint`` pays that only when a
    plugin is installed. A path entry that is a zip is looked into the same way."""
    for entry in path:
        folder = entry or "."
        try:
            with os.scandir(folder) as found:
                infos = [e.path for e in found if e.name.endswith((".dist-info", ".egg-info"))]
        except NotADirectoryError:
            if _zip_declares(folder):
                return True
            continue
        except OSError:  # a path entry that does not exist (yet)
            continue
        for info in infos:
            try:
                with open(os.path.join(info, "entry_points.txt"), encoding="utf-8",
                          errors="replace") as f:
                    if _SECTION.search(f.read()):
                        return True
            except OSError:  # no entry points, or an egg-info that is a file
                continue
    return False


def _zip_declares(archive: str) -> bool:
    """:func:`_declared` for a zip on the import path (True when it cannot be read: then
    :mod:`importlib.metadata` decides)."""
    import zipfile

    try:
        with zipfile.ZipFile(archive) as z:
            for name in z.namelist():
                if name.endswith("-info/entry_points.txt") and name.count("/") == 1 and \
                        _SECTION.search(z.read(name).decode("utf-8", "replace")):
                    return True
    except (OSError, zipfile.BadZipFile):
        return True
    return False


@cached(maxsize=4)
def _load(off: bool, path: tuple[str, ...]) -> tuple[tuple[Plugin, ...], tuple[Broken, ...]]:
    if off or not _declared(path):
        return (), ()
    from importlib import metadata  # here: `import aou_dsl` and `aouc lint` stay light

    good: list[Plugin] = []
    bad: list[Broken] = []
    for ep in sorted(metadata.entry_points(group=GROUP), key=lambda e: (e.name, e.value)):
        try:
            obj = ep.load()  # safe: the name comes from installed metadata, not a file
        except Exception as exc:  # a plugin's import may fail in any way: report it
            bad.append(Broken(ep.name, _source(ep), f"{type(exc).__name__}: {exc}"))
            continue
        parts = {layer: getattr(obj, layer) for layer in LAYERS
                 if getattr(obj, layer, None) is not None}
        if "kind" not in parts:
            bad.append(Broken(ep.name, _source(ep), "it gives no `kind` part"))
            continue
        good.append(Plugin(ep.name, _source(ep), parts))
    return tuple(good), tuple(bad)


loaded.cache_clear = _load.cache_clear  # type: ignore[attr-defined]


def plugins() -> tuple[Plugin, ...]:
    """The plugins that loaded."""
    return loaded()[0]


def part(kind: str, layer: str) -> object | None:
    """The part for ``layer`` of the plugin whose kind is ``kind``, or None (no such
    plugin, or it gives nothing for that layer)."""
    for p in plugins():
        if p.name == kind:
            return p.part(layer)
    return None
