"""The files a command reads, for the output rule (:func:`aou_dsl.core.files.guard_output`).

A command that writes must not write over anything it reads. What it reads is more than
the files on its command line: a ``.aou`` file names its robot file (``robot "arm.toml"``,
unless ``--robot`` overrides it), a robot description names its URDF (``urdf = ...``),
and a URDF names its meshes. :func:`files_read` follows that chain. It reads only what
it must to follow it (the ``robot`` settings, the description's ``urdf``, the URDF's mesh
names), only regular files, and at most :data:`LIMIT` bytes of each: a file it cannot
follow is left to the command, which says what is wrong with it.

A ``.aou`` file's robot files are those of its parsed statements, as the linter reads
them: a ``robot`` setting anywhere the grammar accepts one (after a ``;`` on one line,
after a form feed) is seen. A file that does not parse loads no robot; its text is
then searched for every quoted name after ``robot`` all the same.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable

__all__ = ["LIMIT", "files_read", "robot_files"]

#: The most bytes read of one file to follow the chain (larger files are not followed).
LIMIT = 64 << 20

#: A quoted name after ``robot`` anywhere in a text (comments too): the robot files of a
#: file that does not parse, where more is kept than the command could read.
#: Every robot statement naming a file matches it too (only blanks may stand between
#: the keyword and its quoted name), so a text without a match needs no parse.
_ROBOT_ANYWHERE = re.compile(r'\brobot\s*"([^"\n]+)"')


def _head(path: str) -> str | None:
    """The text of the regular file ``path`` (None: not one, too large or unreadable)."""
    try:
        if not os.path.isfile(path) or os.path.getsize(path) > LIMIT:
            return None
        with open(path, "rb") as fh:
            return fh.read(LIMIT).decode("utf-8", "replace")
    except OSError:
        return None


def _robot_names(text: str, path: str) -> list[str]:
    """The quoted robot names of the ``robot`` statements of ``text``, parsed as the
    linter parses it (every name after ``robot`` when it does not parse)."""
    from ..core.diagnostics import AouError
    from ..lang.parse import SequenceBlock, Word, parse

    anywhere = _ROBOT_ANYWHERE.findall(text)
    if not anywhere:  # no robot file named (`robot panda`, or none): nothing to parse
        return []
    try:
        tree = parse(text, path)
    except AouError:
        return anywhere
    statements = [s for item in tree.items for s in (
        item.statements if isinstance(item, SequenceBlock) else (item,))]
    return [a.text for s in statements if s.keyword == "robot"
            for a in s.args if isinstance(a, Word) and a.quoted]


def _aou_robots(path: str) -> list[str]:
    """The robot files a ``.aou`` file names, joined to its folder as the linter does."""
    text = _head(path)
    if text is None:
        return []
    folder = os.path.dirname(path)
    return [r if os.path.isabs(r) else os.path.normpath(os.path.join(folder, r))
            for r in _robot_names(text, path)]


def _urdf_of(robot: str) -> tuple[str | None, tuple[str, ...]]:
    """The URDF a robot (a built-in name, a URDF or a description) loads, and the
    description's ``package_dirs``."""
    from ..core.robot_specs import ROBOTS

    if robot in ROBOTS:
        return _builtin_urdf(ROBOTS[robot].urdf), ()
    if not robot.lower().endswith(".toml"):
        return robot, ()
    if _head(robot) is None:
        return None, ()
    try:
        from .description import read_description

        desc = read_description(robot)
    except Exception:  # noqa: BLE001 - the command itself says what is wrong with it
        return None, ()
    if desc.robot:
        return (_builtin_urdf(ROBOTS[desc.robot].urdf) if desc.robot in ROBOTS else None,
                tuple(desc.package_dirs))
    return desc.urdf, tuple(desc.package_dirs)


def _builtin_urdf(sub: str) -> str | None:
    try:
        import example_robot_data as erd

        return os.path.join(erd.getModelPath(sub), sub)
    except Exception:  # noqa: BLE001 - not installed: nothing there to protect
        return None


def _meshes(urdf: str, package_dirs: Iterable[str], missing: list[str] | None = None
            ) -> list[str]:
    """The mesh files a URDF names that exist (as PyBullet would load them); the URIs
    that name none are appended to ``missing`` when given."""
    import xml.etree.ElementTree as ET

    from .urdf import resolve_uri

    text = _head(urdf)
    if text is None:
        return []
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return []
    folder = os.path.dirname(os.path.abspath(urdf))
    out = []
    for uri in sorted({m.get("filename", "") for m in root.iter("mesh")} - {""}):
        try:
            path = resolve_uri(uri, folder, tuple(package_dirs))
        except Exception:  # noqa: BLE001 - a URI aou refuses is reported by the command
            path = None
        if path is not None:
            out.append(path)
        elif missing is not None:
            missing.append(uri)
    return out


def robot_files(robot: str, package_dirs: Iterable[str] = (),
                missing: list[str] | None = None) -> list[str]:
    """The files loading ``robot`` reads: the robot file itself (unless a built-in name),
    the URDF and its meshes; the URIs of the meshes it names that are not there are
    appended to ``missing`` when given (a file that appears later is read then)."""
    from ..core.robot_specs import ROBOTS

    out = [] if robot in ROBOTS else [robot]
    urdf, dirs = _urdf_of(robot)
    if urdf is not None:
        out.append(urdf)
        out += _meshes(urdf, (*dirs, *package_dirs), missing)
    return out


def files_read(paths: Iterable[str] = (), robot: str | None = None,
               package_dirs: Iterable[str] = ()) -> list[str]:
    """Every file a command reads: ``paths`` (``.aou`` files, trajectories, recordings),
    ``robot`` (the command line's ``--robot``) and the robot files the ``.aou`` files
    name (looked at even when ``--robot`` overrides them), the URDFs those load and the
    URDFs' meshes; each once, in that order."""
    paths = list(paths)
    robots = ([robot] if robot else []) + [r for p in paths if p.lower().endswith(".aou")
                                           for r in _aou_robots(p)]
    out: list[str] = []
    for f in [*paths, *(f for r in dict.fromkeys(robots) for f in robot_files(
            r, package_dirs))]:
        if f not in out:
            out.append(f)
    return out
