"""What a URDF must be before aou works with it: one tree of links, of a bounded size,
whose joints have limits and axes an arm can have, and whose ``package://`` paths stay
inside their packages.

Files come from vendors and from people's hands. A cycle, a self-loop or a second root
is refused with V109 before any walk of the tree could loop; so are velocity limits of
zero or below, a lower limit above the upper, effort limits below zero (zero on an arm
joint), a zero or enormous joint axis, and numbers that are not finite. A file with
more than :data:`MAX_LINKS` links or joints, or a chain deeper than :data:`MAX_DEPTH`, is
V132: the work of loading an arm grows with its joints. A package path that climbs out of
its package (``package://arm/../../etc/passwd``), or names no package
(``package://../etc/passwd``), is V131; one that does not resolve inside a package that
exists (:func:`aou_dsl.robot.urdf.resolve_uri`) is a mesh not found.
"""

from __future__ import annotations

import math
import os
import posixpath
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from typing import Any

from ..core.codes import V109, V131, V132
from ..core.diagnostics import AouError, Span, diag
from .chain import MAX_ARM_JOINTS
from .urdf_model import Joint, Urdf

__all__ = ["MAX_ARM_JOINTS", "MAX_DEPTH", "MAX_LINKS", "check_mesh_paths", "check_urdf",
           "package_parts"]

#: Most links (and most joints) of a URDF aou loads.
MAX_LINKS = 1000
#: Deepest chain of links from the root.
MAX_DEPTH = 64
#: Largest coordinate of a joint origin [m] and length of a joint axis.
_MAX_OFFSET = 100.0
_AXIS = (1e-6, 1e6)
#: Largest position limit [rad or m] and velocity limit [rad/s or m/s]; largest effort.
_MAX_LIMIT, _MAX_EFFORT = 1e4, 1e7


def _bad(urdf: Urdf, message: str, hint: str | None = None, code: str = V109,
         **fields: Any) -> AouError:
    return AouError(diag(code, f"`{os.path.basename(urdf.path)}`: {message}",
                         Span.whole_file(urdf.path), hint=hint, **fields))


def _tree(urdf: Urdf) -> None:
    """One root; every joint between two known, different links; each link the child of
    one joint at most; every link reached from the root; a bounded size and depth."""
    if len(urdf.links) > MAX_LINKS or len(urdf.joints) > MAX_LINKS:
        raise _bad(urdf, f"{len(urdf.links)} links and {len(urdf.joints)} joints; aou loads "
                   f"robots of at most {MAX_LINKS} of each", code=V132, limit=MAX_LINKS)
    known = set(urdf.links)
    if len(known) != len(urdf.links):
        twice = next(n for n in urdf.links if urdf.links.count(n) > 1)
        raise _bad(urdf, f"two links are named `{twice}`")
    parent_of: dict[str, str] = {}
    for j in urdf.joints:
        for end in (j.parent, j.child):
            if end not in known:
                raise _bad(urdf, f"joint `{j.name}` names link `{end}`, which the file does "
                           "not have")
        if j.parent == j.child:
            raise _bad(urdf, f"joint `{j.name}` joins link `{j.child}` to itself")
        if j.child in parent_of:
            raise _bad(urdf, f"link `{j.child}` is the child of two joints; a URDF is a tree")
        parent_of[j.child] = j.parent
    roots = [n for n in urdf.links if n not in parent_of]
    if len(roots) != 1:
        found = ", ".join(f"`{r}`" for r in roots[:3]) + (" ..." if len(roots) > 3 else "")
        raise _bad(urdf, "the joints make a cycle: no link is the root" if not roots else
                   f"{len(roots)} links have no parent ({found}); a robot has one root link",
                   hint="a URDF is one tree: every link but the root is the child of one "
                        "joint")
    children: dict[str, list[str]] = {}
    for child, parent in parent_of.items():
        children.setdefault(parent, []).append(child)
    depth, frontier, seen = 0, [roots[0]], 1
    while frontier:
        frontier = [c for link in frontier for c in children.get(link, ())]
        seen += len(frontier)
        depth += bool(frontier)
        if depth > MAX_DEPTH:
            raise _bad(urdf, f"a chain more than {MAX_DEPTH} links deep; aou loads arms of "
                       f"at most {MAX_ARM_JOINTS} joints", code=V132, limit=MAX_DEPTH)
    if seen != len(urdf.links):
        raise _bad(urdf, "some joints make a cycle, apart from the tree of the root link "
                   f"`{roots[0]}`")


def _finite(values: Iterable[float | None]) -> bool:
    return all(v is None or math.isfinite(v) for v in values)


def _gripper(j: Joint) -> bool:
    from .chain import is_gripper

    return is_gripper(j.name)


def _joint(urdf: Urdf, j: Joint) -> str | None:
    """What is wrong with joint ``j``'s numbers, or None."""
    if not _finite((*j.xyz, *j.rpy, *j.axis, j.lower, j.upper, j.velocity, j.effort)):
        return "a number that is not finite (nan or inf)"
    if max(abs(c) for c in j.xyz) > _MAX_OFFSET:
        return f"an origin more than {_MAX_OFFSET:g} m from its parent"
    if not j.moving:
        return None
    size = max(abs(c) for c in j.axis)
    if not _AXIS[0] <= size <= _AXIS[1]:
        return f"the axis `{' '.join(f'{c:g}' for c in j.axis)}`: an axis is a direction, " \
               "a vector of length 1"
    arm = not _gripper(j)
    if j.velocity is not None and (j.velocity < 0 or arm and j.velocity == 0 or
                                   j.velocity > _MAX_LIMIT):
        return f"a velocity limit of {j.velocity:g}: it must be above 0 and at most " \
               f"{_MAX_LIMIT:g}"
    if j.effort is not None and (j.effort < 0 or arm and j.effort == 0 or
                                 j.effort > _MAX_EFFORT):
        return f"an effort limit of {j.effort:g}: it must be above 0 and at most " \
               f"{_MAX_EFFORT:g} (leave the attribute out for a joint whose effort is not " \
               "known)"
    if max(abs(j.lower or 0.0), abs(j.upper or 0.0)) > _MAX_LIMIT:
        return f"a position limit beyond {_MAX_LIMIT:g}"
    if j.type != "continuous" and j.lower is not None and j.upper is not None \
            and j.lower > j.upper:
        return f"a lower limit ({j.lower:g}) above its upper limit ({j.upper:g})"
    return None


def package_parts(uri: str) -> tuple[str, str] | None:
    """The package and the path inside it of a ``package://`` ``uri`` (vendors write
    ``package:///NAME/...`` for ``package://NAME/...``); None when it names no package
    (``package://../x``, ``package://./x``) or climbs out of it (``..`` steps, an
    absolute path, a drive or a backslash)."""
    body = uri[len("package://"):]
    body = body[1:] if body.startswith("/") else body
    package, _, rest = body.partition("/")
    clean = posixpath.normpath(rest) if rest else ""
    if package in ("", ".", "..") or "\\" in package or ":" in package or not rest or \
            rest.startswith("/") or clean == ".." or clean.startswith("../") or \
            "\\" in rest or ":" in rest:
        return None
    return package, rest


def check_mesh_paths(urdf: Urdf) -> None:
    """Refuse (V131) a ``package://`` mesh path that climbs out of its package or
    names none (:func:`package_parts`)."""
    try:
        root = ET.fromstring(urdf.text)
    except ET.ParseError:
        return
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename", "")
        if uri.startswith("package://") and package_parts(uri) is None:
            raise _bad(urdf, f"the mesh path `{uri}` leaves its package", code=V131,
                       hint="a package:// path names a file inside a package: "
                            "package://NAME/..., without `..` steps that climb out of it",
                       found=uri)


def check_urdf(urdf: Urdf) -> None:
    """Every check of the module's docstring.

    Raises:
        AouError: V109, V131 or V132 naming the first problem.
    """
    _tree(urdf)
    for j in urdf.joints:
        problem = _joint(urdf, j)
        if problem is not None:
            raise _bad(urdf, f"joint `{j.name}` has {problem}",
                       hint="correct the joint's <limit>, <axis> or <origin> in the URDF")
    check_mesh_paths(urdf)
