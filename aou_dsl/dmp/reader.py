"""Reading a ``.dmp`` folder as untrusted input: aou's own schema-checked reader.

A ``.dmp`` folder is meant to be shared between labs, so nothing in it is trusted. The
library's ``movement_primitives.io.read_json`` imports whatever module and class a part
file names and calls it with the file's arguments: it is never used here. Instead:

- **The folder is closed.** The manifest and every part it names are resolved (symlinks
  followed) and must lie inside the folder; a part path is relative, without ``..``. Only
  regular files are opened (a FIFO, a device or a socket is refused before it is
  opened), and never more than their bound (``MAX_MANIFEST_BYTES``,
  ``MAX_PART_BYTES``, ``MAX_FOLDER_BYTES`` in all).
- **Every field is checked** (:mod:`.schema`) before anything uses it: its type, its
  range, its size; every number finite; the robot, its end-effector frame and its
  shiver joint exist in the arm; the goal differs from the start; the parts are a list
  of at most ``MAX_PARTS``, naming no file twice; the descriptors are the registry's.
- **The library's objects are built from an allow-list** (``schema.ALLOWED``): a part's
  ``module`` and ``class`` must name ``CartesianDMP`` (and its two ``ForcingTerm``
  fields ``ForcingTerm``); the object is constructed from the checked arguments and the
  checked weights are copied in. Nothing named in a file is imported.
- **Every number the library loops on is bounded** (:mod:`.bounds`): the execution
  time, the integration step ``int_dt``, the rollout's steps, the basis functions, the
  rate and the samples.

A failure is a diagnostic naming the file and the field: D602 for a field that is not
what the format says, D607 for a part naming a class outside the allow-list, D608 for a
folder that is not closed (a path outside it, a special file, a size or count beyond
its bound). Nothing here imports ``movement_primitives`` until every part has passed.
"""

from __future__ import annotations

import json
import os
import stat
from typing import Any

from ..core.codes import D608, I501
from ..core.diagnostics import AouError, Span, diag
from .bounds import MAX_FOLDER_BYTES, MAX_MANIFEST_BYTES, MAX_NAME, MAX_PART_BYTES
from .schema import Where, build_dmp, check_manifest, check_part, kind_of

__all__ = ["read_folder"]


# --- reading files inside the folder ----------------------------------------------------

def _inside(folder: str, rel: Any, w: Where, field: str) -> str:
    """The real path of ``rel`` (a part's ``file``), which must lie inside ``folder``."""
    if not isinstance(rel, str) or not rel or len(rel) > MAX_NAME or "\0" in rel:
        raise w.fail(field, f"must be a relative path inside the folder, found {kind_of(rel)}")
    parts = rel.replace("\\", "/").split("/")
    if os.path.isabs(rel) or rel.startswith(("/", "\\")) or ".." in parts:
        raise w.fail(field, f"`{rel}` leads outside the .dmp folder (an absolute path "
                     "or `..`)", code=D608)
    real = os.path.realpath(os.path.join(folder, rel))
    if not real.startswith(folder + os.sep):
        raise w.fail(field, f"`{rel}` resolves to `{real}`, outside the .dmp folder",
                     code=D608)
    return real


def _special(mode: int) -> str | None:
    for test, name in ((stat.S_ISDIR, "folder"), (stat.S_ISCHR, "character device"),
                       (stat.S_ISBLK, "block device"), (stat.S_ISFIFO, "FIFO (named pipe)"),
                       (stat.S_ISSOCK, "socket")):
        if test(mode):
            return name
    return None if stat.S_ISREG(mode) else "special file"


def _read_bounded(real: str, shown: str, limit: int, w: Where, field: str) -> bytes:
    """The bytes of the regular file ``real``, at most ``limit`` of them. A special file
    is refused before it is opened (and again after, should it have been swapped)."""
    try:
        kind = _special(os.stat(real).st_mode)
        if kind is not None:
            raise w.fail(field, f"`{shown}` is a {kind}, not a regular file", code=D608,
                         hint="a .dmp folder holds regular files only")
        # Not following a link swapped in since the path was resolved (ELOOP: I501).
        fd = os.open(real, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0)
                     | getattr(os, "O_NOFOLLOW", 0))
    except FileNotFoundError:
        if field:
            raise w.fail(field, f"names `{shown}`, which is missing") from None
        raise AouError(diag(I501, f"cannot read `{shown}`: no such file",
                            Span.whole_file(w.path))) from None
    except OSError as exc:
        raise AouError(diag(I501, f"cannot read `{shown}`: {exc.strerror or exc}",
                            Span.whole_file(w.path))) from None
    try:
        st = os.fstat(fd)
        kind = _special(st.st_mode)
        if kind is not None:
            raise w.fail(field, f"`{shown}` is a {kind}, not a regular file", code=D608,
                         hint="a .dmp folder holds regular files only")
        if st.st_size > limit:
            raise w.fail(field, f"`{shown}` is {st.st_size} bytes, more than the "
                         f"{limit} a .dmp file may have", code=D608)
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > limit:
            raise w.fail(field, f"`{shown}` is more than the {limit} bytes a .dmp file "
                         "may have", code=D608)
        return b"".join(chunks)
    except OSError as exc:
        raise AouError(diag(I501, f"cannot read `{shown}`: {exc.strerror or exc}",
                            Span.whole_file(w.path))) from None
    finally:
        os.close(fd)


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a number JSON allows")


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise ValueError(f"the key {k!r} appears twice in one object")
        out[k] = v
    return out


def _json(data: bytes, w: Where) -> Any:
    """The JSON document ``data``: strict (no NaN or Infinity, no key twice in an
    object), bounded in depth by the parser's recursion limit."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise w.fail("", f"is not UTF-8 text (byte {exc.start})") from None
    try:
        return json.loads(text, parse_constant=_no_constant,
                          object_pairs_hook=_no_duplicates)
    except RecursionError:
        raise w.fail("", "is not JSON the format allows: nested too deeply") from None
    except ValueError as exc:
        raise w.fail("", f"is not JSON the format allows: {exc}") from None


# --- the folder -------------------------------------------------------------------------

def read_folder(path: str) -> tuple[dict[str, Any], list[Any]]:
    """The checked manifest of the ``.dmp`` folder ``path`` and the DMP of each part
    (None for a hold or a shiver), its robot, frame and shiver joint checked against the
    arm; the manifest's ``files`` are the files read.

    Raises:
        AouError: I501 when the folder or a file cannot be read; D602, D607, D608 (see the
            module's docstring).
    """
    shown = os.path.join(path, "manifest.json")
    w = Where(shown)
    if not os.path.isdir(path):
        raise AouError(diag(I501, f"cannot read the .dmp folder `{path}`: "
                            f"{'no such folder' if not os.path.lexists(path) else 'not a folder'}",
                            Span.whole_file(path)))
    folder = os.path.realpath(path)
    real = _inside(folder, "manifest.json", w, "")
    data = _read_bounded(real, shown, MAX_MANIFEST_BYTES, w, "")
    doc = check_manifest(_json(data, w), w)
    _check_arm(doc, w)
    budget = MAX_FOLDER_BYTES - len(data)
    dmps: list[Any] = []
    checked: list[dict[str, Any] | None] = []
    doc["files"] = [shown]
    for i, e in enumerate(doc["parts"]):
        if e["file"] is None:
            checked.append(None)
            continue
        field = f"parts[{i}].file"
        name = _inside(folder, e["file"], w, field)
        pw = Where(os.path.join(path, e["file"]))
        doc["files"].append(pw.path)
        raw = _read_bounded(name, pw.path, min(MAX_PART_BYTES, budget), w, field)
        budget -= len(raw)
        checked.append(check_part(_json(raw, pw), pw))
    for args in checked:
        dmps.append(None if args is None else build_dmp(args))
    return doc, dmps


def _check_arm(doc: dict[str, Any], w: Where) -> None:
    """The robot loads, has the frame, the joints and the shiver joint the manifest
    names."""
    from ..core.robot_specs import ROBOTS, is_robot_file
    from ..robot.load import load_arm, load_robot

    robot = doc["robot"]
    if robot not in ROBOTS:
        if not is_robot_file(robot):
            raise w.fail("robot", f"names no robot aou knows: `{robot}` (expected one of "
                         f"{', '.join(ROBOTS)}, or a robot file)")
        try:
            mode = os.stat(robot).st_mode
        except (OSError, ValueError):
            raise w.fail("robot", f"names the robot file `{robot}`, which does not exist "
                         "on this machine") from None
        if not stat.S_ISREG(mode):
            raise w.fail("robot", f"names `{robot}`, which is not a regular file", code=D608)
    try:
        load_robot(robot)
    except AouError as err:
        raise w.fail("robot", f"names a robot aou cannot load: "
                     f"{err.diagnostics[0].message}") from None
    try:
        arm = load_arm(robot, doc["ee_frame"])
    except AouError as err:
        raise w.fail("ee_frame", f"is not a frame of the robot: "
                     f"{err.diagnostics[0].message}") from None
    if doc["shiver_joint"] not in arm.joint_names:
        raise w.fail("shiver_joint", f"`{doc['shiver_joint']}` is not a joint of the arm "
                     f"(its joints: {', '.join(arm.joint_names)})")
    if tuple(doc["joint_names"]) != tuple(arm.joint_names):
        raise w.fail("joint_names", f"must be the arm's joints in order "
                     f"({', '.join(arm.joint_names)})")
