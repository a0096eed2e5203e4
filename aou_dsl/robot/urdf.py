"""A URDF as vendors ship it: its kinematic tree, its ``package://`` paths, and the two
copies aou loads.

- :func:`read_urdf` parses the file into joints and links (no heavy imports).
- :func:`resolve_uri` finds a ``package://pkg/...`` mesh: in the folders given, in the
  URDF's folder and its parents (a folder named ``pkg``, or holding one), in
  ``ROS_PACKAGE_PATH``; a package copied out of its install is found by the longest tail
  of the path under a folder given, the URDF's folder or one of its two parents. Never
  outside the package, links resolved.
- :func:`kinematic_xml` is the copy Pinocchio builds the kinematics from: continuous
  joints become revolute joints of :data:`CONTINUOUS_RANGE` (one angle each), missing
  velocity limits are filled in, and no mesh is read.
- :func:`scene_xml` is the copy PyBullet loads: every mesh path absolute, visual shapes
  kept only when asked (rendering), so the checks load collision meshes only.

Both copies may end in an extra frame (:data:`GAZE_FRAME`) whose z axis is the
end-effector's forward axis, for arms whose end-effector link looks along another axis.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence

from ..core.codes import V109
from ..core.diagnostics import AouError, Span, diag
from ..core.inputs import check_size, read_input_text
from .sanity import check_urdf, package_parts
from .urdf_model import CONTINUOUS_RANGE, GAZE_FRAME, MOVING, Gaze, Joint, Urdf

__all__ = ["CONTINUOUS_RANGE", "GAZE_FRAME", "MOVING", "Gaze", "Joint", "Urdf", "gaze_rpy",
           "kinematic_xml", "gaze_offset", "read_urdf", "resolve_uri", "scene_xml", "unlimited"]

def _bad(path: str, message: str, hint: str | None = None) -> AouError:
    return AouError(diag(V109, message, Span.whole_file(path), hint=hint))


def _vec3(text: str | None, default: tuple[float, float, float]
          ) -> tuple[float, float, float]:
    if text is None:
        return default
    parts = text.split()
    if len(parts) != 3:
        raise ValueError(f"`{text}` is not 3 numbers")
    return float(parts[0]), float(parts[1]), float(parts[2])


def _num(el: ET.Element | None, key: str) -> float | None:
    if el is None or el.get(key) is None:
        return None
    return float(el.get(key, ""))


def _joint(el: ET.Element) -> Joint:
    origin, axis, limit = el.find("origin"), el.find("axis"), el.find("limit")
    parent, child = el.find("parent"), el.find("child")
    if parent is None or child is None:
        raise ValueError(f"joint `{el.get('name')}` lacks a parent or a child link")
    return Joint(
        name=el.get("name", ""), type=el.get("type", ""),
        parent=parent.get("link", ""), child=child.get("link", ""),
        xyz=_vec3(origin.get("xyz") if origin is not None else None, (0.0, 0.0, 0.0)),
        rpy=_vec3(origin.get("rpy") if origin is not None else None, (0.0, 0.0, 0.0)),
        axis=_vec3(axis.get("xyz") if axis is not None else None, (1.0, 0.0, 0.0)),
        lower=_num(limit, "lower"), upper=_num(limit, "upper"),
        velocity=_num(limit, "velocity"), effort=_num(limit, "effort"))


def read_urdf(path: str) -> Urdf:
    """Parse a URDF file.

    Raises:
        AouError: I501 when it cannot be read, V109 when it is not a URDF aou can use.
    """
    path = os.path.abspath(path)
    text = read_input_text(path, "robot", "the robot file")
    try:
        root = ET.fromstring(text)
        if root.tag != "robot":
            raise ValueError(f"the root element is <{root.tag}>, not <robot>")
        joints = tuple(_joint(el) for el in root.findall("joint"))
    except (ET.ParseError, ValueError) as exc:
        raise _bad(path, f"`{os.path.basename(path)}` is not a URDF aou can read: {exc}",
                   "a robot file is a URDF (.urdf) or a robot description (.toml)") from None
    links = tuple(el.get("name", "") for el in root.findall("link"))
    if not links:
        raise _bad(path, f"`{os.path.basename(path)}` has no links")
    colliding = frozenset(el.get("name", "") for el in root.findall("link")
                          if el.find("collision") is not None)
    urdf = Urdf(path, text, joints, links, colliding)
    check_urdf(urdf)
    return urdf


def _package_dirs(package: str, folder: str, extra: Sequence[str]) -> list[str]:
    """Candidate folders of ``package``, in the order they are searched."""
    out: list[str] = []
    ancestors = []
    d = os.path.abspath(folder)
    while os.path.dirname(d) != d:  # never the file system's root: /etc is no package
        ancestors.append(d)
        d = os.path.dirname(d)
    ros = [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    for base in [*extra, *ancestors, *ros]:
        base = os.path.abspath(base)
        if os.path.basename(base) == package:
            out.append(base)
        out.append(os.path.join(base, package))
    return out


def _inside(path: str, folder: str) -> bool:
    """Whether ``path`` is inside ``folder``, both with their links resolved."""
    real, top = os.path.realpath(path), os.path.realpath(folder)
    return real == top or real.startswith(top.rstrip(os.sep) + os.sep)


def resolve_uri(uri: str, folder: str, package_dirs: Sequence[str] = ()) -> str | None:
    """The absolute path of a mesh ``uri`` written in a URDF that lives in ``folder``;
    None when no regular file is found (a folder or a FIFO is none; see the module's
    docstring for the search).

    A ``package://`` path resolves only inside a package that exists: a folder named as
    the package on the search path, or, for a package copied out of its install, a
    folder given in ``package_dirs`` or the folder holding the URDF (or one of its
    :data:`COPIED_DEPTH` parents) holding the longest tail of the path. The file, its
    links resolved, must lie inside that folder (its links resolved too):
    ``package://../x``, a package that does not exist and a link out of the package
    resolve to nothing.
    """
    if uri.startswith("file://"):
        uri = uri[len("file://"):]
    if not uri.startswith("package://"):
        path = uri if os.path.isabs(uri) else os.path.join(folder, uri)
        return os.path.normpath(path) if os.path.isfile(path) else None
    parts = package_parts(uri)
    if parts is None:
        return None
    package, rest = parts
    for d in _package_dirs(package, folder, package_dirs):
        path = os.path.join(d, rest)
        if os.path.isdir(d) and os.path.isfile(path) and _inside(path, d):
            return os.path.normpath(path)
    tail = rest.split("/")
    roots = [*package_dirs, *_copied_roots(folder)]
    for k in range(len(tail) - 1):  # the longest tail first
        for root in roots:
            path = os.path.join(root, *tail[k:])
            if os.path.isfile(path) and _inside(path, root):
                return os.path.normpath(os.path.abspath(path))
    return None


#: How many parents of a URDF's folder may be the root of the package holding it, copied
#: out of its install under another name (``pkg/urdf/sub/arm.urdf``: ``pkg``).
COPIED_DEPTH = 2


def _copied_roots(folder: str) -> list[str]:
    """The folders that may be the package holding a URDF in ``folder``: it and its
    :data:`COPIED_DEPTH` parents, never the file system's root."""
    out = [os.path.abspath(folder), *_parents(folder)][:COPIED_DEPTH + 1]
    return [d for d in out if os.path.dirname(d) != d]


def _parents(folder: str) -> list[str]:
    out, d = [], os.path.abspath(folder)
    while os.path.dirname(d) != d:
        d = os.path.dirname(d)
        out.append(d)
    return out


def gaze_rpy(forward: str, roll: float = 0.0) -> tuple[float, float, float]:
    """Roll, pitch, yaw of the frame whose z axis is the link's axis ``forward``
    (``"+x"``, ``"-y"``, ...) and whose x axis is the next axis of x, y, z after it,
    turned by ``roll`` [rad] about z."""
    i = "xyz".index(forward[1])
    sign = -1.0 if forward[0] == "-" else 1.0
    z = [0.0, 0.0, 0.0]
    z[i] = sign
    x0 = [0.0, 0.0, 0.0]
    x0[(i + 1) % 3] = 1.0
    y0 = [z[1] * x0[2] - z[2] * x0[1], z[2] * x0[0] - z[0] * x0[2], z[0] * x0[1] - z[1] * x0[0]]
    c, s = math.cos(roll), math.sin(roll)
    x = [c * a + s * b for a, b in zip(x0, y0, strict=True)]
    y = [c * b - s * a for a, b in zip(x0, y0, strict=True)]
    r = [[x[k], y[k], z[k]] for k in range(3)]  # rows of the matrix with columns x, y, z
    pitch = math.asin(max(-1.0, min(1.0, -r[2][0])))
    if abs(r[2][0]) < 1.0 - 1e-12:
        roll = math.atan2(r[2][1], r[2][2])
        yaw = math.atan2(r[1][0], r[0][0])
    else:  # gimbal lock: put the whole turn into yaw
        roll = 0.0
        yaw = math.atan2(-r[0][1], r[1][1])
    return roll, pitch, yaw


def _fmt(v: float) -> str:
    return repr(float(v))


def unlimited(j: Joint) -> bool:
    """A joint that turns without end: continuous, or revolute without a position range
    (no limits, or lower >= upper, which URDF parsers read as none)."""
    if j.type == "continuous":
        return True
    return j.type == "revolute" and (j.lower is None or j.upper is None or j.lower >= j.upper)


def gaze_offset(forward: str, offset: float) -> tuple[float, float, float]:
    """``offset`` [m] along the link's axis ``forward``, as a vector in the link."""
    v = [0.0, 0.0, 0.0]
    v["xyz".index(forward[1])] = -offset if forward[0] == "-" else offset
    return v[0], v[1], v[2]


def _add_gaze(root: ET.Element, ee_link: str, forward: str, offset: float, roll: float
              ) -> None:
    """Append the :data:`GAZE_FRAME` link, welded to ``ee_link`` ``offset`` [m] ahead
    of its origin, z along its axis ``forward``, turned by ``roll`` about it."""
    link = ET.SubElement(root, "link", {"name": GAZE_FRAME})
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "mass", {"value": "1e-06"})
    ET.SubElement(inertial, "inertia", {k: ("1e-12" if k[1] == k[2] else "0")
                                        for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")})
    joint = ET.SubElement(root, "joint", {"name": f"{GAZE_FRAME}_joint", "type": "fixed"})
    ET.SubElement(joint, "parent", {"link": ee_link})
    ET.SubElement(joint, "child", {"link": GAZE_FRAME})
    xyz = " ".join(_fmt(c) for c in gaze_offset(forward, offset))
    ET.SubElement(joint, "origin", {"xyz": xyz,
                                    "rpy": " ".join(_fmt(a) for a in gaze_rpy(forward, roll))})


def kinematic_xml(urdf: Urdf, arm: Sequence[str], velocity: dict[str, float]) -> str:
    """The URDF text Pinocchio builds the kinematics of the arm from (see the module's
    docstring): every joint not in ``arm`` welded at its zero position, no shapes.

    Args:
        urdf: the robot.
        arm: the arm's joints.
        velocity: velocity limits [rad/s or m/s] for joints whose URDF gives none.
    """
    root = ET.fromstring(urdf.text)
    for el in root.findall("link"):
        for tag in ("visual", "collision"):
            for child in el.findall(tag):
                el.remove(child)
    for el in root.findall("joint"):
        name = el.get("name", "")
        if name not in arm:
            el.set("type", "fixed")
            continue
        limit = el.find("limit")
        if limit is None:
            limit = ET.SubElement(el, "limit")
        if unlimited(urdf.joint(name)):
            el.set("type", "revolute")
            limit.set("lower", _fmt(-CONTINUOUS_RANGE))
            limit.set("upper", _fmt(CONTINUOUS_RANGE))
        if name in velocity:
            limit.set("velocity", _fmt(velocity[name]))
        for key in ("effort", "lower", "upper"):
            limit.set(key, limit.get(key, "0"))
    return ET.tostring(root, encoding="unicode")


def scene_xml(urdf: Urdf, package_dirs: Sequence[str], gaze: Gaze | None, *,
              visuals: bool) -> tuple[str, list[str]]:
    """The URDF text PyBullet loads, and the mesh paths that could not be found.

    Every mesh filename is made absolute; visual shapes are dropped unless ``visuals``
    (the checks need collision shapes only, and visual meshes are the slow part).

    Raises:
        AouError: V132 for a mesh larger than the bound of a mesh file (``AOU_MAX_INPUT_MB``
            raises it; :mod:`aou_dsl.core.inputs`).
    """
    root = ET.fromstring(urdf.text)
    folder = os.path.dirname(urdf.path)
    missing: list[str] = []
    for el in root.findall("link"):
        if not visuals:
            for child in el.findall("visual"):
                el.remove(child)
        for mesh in el.iter("mesh"):
            uri = mesh.get("filename", "")
            path = resolve_uri(uri, folder, package_dirs)
            if path is None:
                missing.append(uri)
            else:
                check_size(path, "mesh", "the mesh")  # PyBullet reads it all
                mesh.set("filename", path)
    if gaze is not None:
        _add_gaze(root, *gaze)
    return ET.tostring(root, encoding="unicode"), missing
