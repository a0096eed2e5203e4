"""Reading a ``.dmp`` folder as untrusted input: aou's own schema-checked reader.

A ``.dmp`` folder is meant to be shared between labs, so nothing in it is trusted. The
library's ``movement_primitives.io.read_json`` imports whatever module and class a part
file names and calls it with the file's arguments: it is never used here. Instead:

- **The folder is closed.** The manifest and every part it names are resolved (symlinks
  followed) and must lie inside the folder; a part path is relative, without ``..``. Only
  regular files are opened (a FIFO, a device or a socket is refused before it is
  opened), and never more than their bound (:data:`MAX_MANIFEST_BYTES`,
  :data:`MAX_PART_BYTES`, :data:`MAX_FOLDER_BYTES` in all).
- **Every field is checked** before anything uses it: its type, its range, its size;
  every number finite; the robot, its end-effector frame and its shiver joint exist in
  the arm; the goal differs from the start; the parts are a list of at most
  :data:`MAX_PARTS`, naming no file twice; the descriptors are the registry's.
- **The library's objects are built from an allow-list** (:data:`ALLOWED`): a part's
  ``module`` and ``class`` must name ``CartesianDMP`` (and its two ``ForcingTerm``
  fields ``ForcingTerm``); the object is constructed from the checked arguments and the
  checked weights are copied in. Nothing named in a file is imported.
- **Every number the library loops on is bounded:** the execution time, the integration
  step ``int_dt``, the rollout's steps, the basis functions, the rate and the samples.

A failure is a diagnostic naming the file and the field: D602 for a field that is not
what the format says, D607 for a part naming a class outside the allow-list, D608 for a
folder that is not closed (a path outside it, a special file, a size or count beyond
its bound). Nothing here imports ``movement_primitives`` until every part has passed.
"""

from __future__ import annotations

import json
import math
import os
import stat
from typing import Any

import numpy as np

from ..core.codes import D602, D607, D608, I501
from ..core.diagnostics import AouError, Span, diag
from .rollout import MIN_GOAL_DISTANCE

__all__ = ["ALLOWED", "MAX_DURATION", "MAX_EXECUTION_TIME", "MAX_FOLDER_BYTES",
           "MAX_INT_DT", "MAX_LEAD", "MAX_MANIFEST_BYTES", "MAX_PARTS", "MAX_PART_BYTES",
           "MAX_RATE", "MAX_SAMPLES", "MAX_STEPS", "MAX_WEIGHTS", "MIN_INT_DT", "MIN_RATE",
           "build_dmp", "check_manifest", "check_part", "read_folder"]

#: Largest manifest read [bytes] (a shipped behaviour's is about 10 kB).
MAX_MANIFEST_BYTES = 4 * 1024 * 1024
#: Largest part file read [bytes] (a shipped motion's is 0.1 to 0.4 MB).
MAX_PART_BYTES = 32 * 1024 * 1024
#: Most bytes read from one folder, manifest and parts together.
MAX_FOLDER_BYTES = 128 * 1024 * 1024
#: Most parts in a manifest (as many as a behaviour file may have episodes).
MAX_PARTS = 1000
#: Longest sequence, and longest part [s] (as long as a behaviour file may move).
MAX_DURATION = 600.0
#: Longest execution time of one part's DMP [s].
MAX_EXECUTION_TIME = 600.0
#: Range of a DMP's integration step ``int_dt`` [s] (aou writes 0.001).
MIN_INT_DT, MAX_INT_DT = 1e-4, 1e-2
#: Most integration steps of one DMP at its own execution time (``execution_time /
#: int_dt``).
MAX_STEPS = 1_000_000
#: Most basis functions per dimension of one DMP (aou writes 400 per second).
MAX_WEIGHTS = 100_000
#: Range of the sample rate [Hz], and most samples of the sequence at its rate.
MIN_RATE, MAX_RATE = 1.0, 1000.0
MAX_SAMPLES = 2_000_000
#: Longest lead-in of a motion's DMP before its episode [s] (aou writes a few
#: milliseconds: three basis functions, or one sample).
MAX_LEAD = 10.0
#: Largest coordinate of a position or goal [m], and largest joint value [rad].
MAX_COORD = 10.0
MAX_JOINT = 100.0
#: Largest transformation-system gain ``alpha_y``, ``beta_y``.
MAX_GAIN = 1e4
#: Longest name (robot, frame, joint, behaviour, file) [characters].
MAX_NAME = 4096

_CARTESIAN = "CartesianDMP"
_TERM = "ForcingTerm"
#: The ``(module, class)`` pairs a part may name, and what each is. Nothing else is
#: built; nothing named in a file is imported.
ALLOWED = {("movement_primitives.dmp._cartesian_dmp", _CARTESIAN): _CARTESIAN,
           ("movement_primitives.dmp", _CARTESIAN): _CARTESIAN,
           ("movement_primitives.dmp._forcing_term", _TERM): _TERM}

_FORMAT = "aou-dmp/1"
_KINDS = ("approach", "retreat", "gaze", "tilt", "pause", "shiver")
_MANIFEST_KEYS = {"format", "behaviour", "state", "intensity", "robot", "ee_frame",
                  "joint_names", "goal", "q_start", "shiver_joint", "rate", "duration",
                  "quaternion_order", "descriptors", "parameters", "parts"}
_MANIFEST_NEEDS = _MANIFEST_KEYS - {"duration", "quaternion_order", "parameters"}
_PART_KEYS = {"kind", "duration", "file", "start", "end", "lead", "values"}
_DMP_KEYS = {"module", "class", "n_dims", "n_vel_dims", "t", "last_t", "start_y", "start_yd",
             "start_ydd", "goal_y", "goal_yd", "goal_ydd", "current_y", "current_yd",
             "initialized", "_execution_time", "dt_", "n_weights_per_dim", "int_dt",
             "smooth_scaling", "forcing_term_pos", "forcing_term_rot", "alpha_y", "beta_y"}
_DMP_NEEDS = {"module", "class", "_execution_time", "dt_", "n_weights_per_dim", "int_dt",
              "forcing_term_pos", "forcing_term_rot", "alpha_y", "beta_y", "start_y",
              "goal_y"}
_TERM_KEYS = {"module", "class", "n_weights_per_dim", "goal_t", "start_t", "overlap",
              "alpha_z", "log_overlap", "execution_time", "weights_", "centers", "widths"}


class _Where:
    """A file and the path of a field in it, for the messages."""

    def __init__(self, path: str, code: str = D602):
        self.path, self.code = path, code

    def fail(self, field: str, what: str, code: str | None = None,
             hint: str | None = None) -> AouError:
        at = f"field `{field}`" if field else "the file"
        return AouError(diag(code or self.code, f"{at} {what}",
                             Span.whole_file(self.path), field=field or None,
                             hint=hint or "write the folder with `aouc compile FILE "
                             "--format dmp`"))


def _kind(x: Any) -> str:
    """What a JSON value is, in words."""
    if x is None:
        return "null"
    if isinstance(x, bool):
        return "a boolean"
    if isinstance(x, int | float):
        return f"the number {x!r}"
    if isinstance(x, str):
        return "a string"
    if isinstance(x, list):
        return f"a list of {len(x)}"
    if isinstance(x, dict):
        return "an object"
    return type(x).__name__


# --- reading files inside the folder ----------------------------------------------------

def _inside(folder: str, rel: Any, w: _Where, field: str) -> str:
    """The real path of ``rel`` (a part's ``file``), which must lie inside ``folder``."""
    if not isinstance(rel, str) or not rel or len(rel) > MAX_NAME or "\0" in rel:
        raise w.fail(field, f"must be a relative path inside the folder, found {_kind(rel)}")
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


def _read_bounded(real: str, shown: str, limit: int, w: _Where, field: str) -> bytes:
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


def _json(data: bytes, w: _Where) -> Any:
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


# --- checking values --------------------------------------------------------------------

def _object(x: Any, w: _Where, field: str, keys: set[str], needs: set[str]) -> dict:
    if not isinstance(x, dict):
        raise w.fail(field, f"must be an object, found {_kind(x)}")
    extra = sorted(set(x) - keys)
    if extra:
        at = f"{field}." if field else ""
        raise w.fail(f"{at}{extra[0]}", "is not a field of the format")
    missing = sorted(needs - set(x))
    if missing:
        at = f"{field}." if field else ""
        raise w.fail(f"{at}{missing[0]}", "is missing")
    return x


def _number(x: Any, w: _Where, field: str, lo: float, hi: float, *,
            above: bool = False, whole: bool = False) -> float:
    """``x`` as a float: a JSON number (not a boolean), finite, in ``[lo, hi]`` (``(lo,
    hi]`` when ``above``), an integer when ``whole``."""
    if isinstance(x, bool) or not isinstance(x, int | float):
        raise w.fail(field, f"must be a number, found {_kind(x)}")
    try:
        v = float(x)
    except OverflowError:
        v = math.inf
    if not math.isfinite(v):
        raise w.fail(field, f"must be a finite number, found {x!r}")
    if whole and v != int(v):
        raise w.fail(field, f"must be a whole number, found {x!r}")
    if v < lo or v > hi or (above and v <= lo):
        raise w.fail(field, f"must be {'above' if above else 'at least'} {lo:g} and at "
                     f"most {hi:g}, found {x!r}")
    return v


def _name(x: Any, w: _Where, field: str, *, null: bool = False) -> str | None:
    if x is None and null:
        return None
    if not isinstance(x, str) or not x or len(x) > MAX_NAME or "\0" in x:
        what = "a name" + (" or null" if null else "")
        raise w.fail(field, f"must be {what}, found {_kind(x)}")
    return x


def _array(x: Any, w: _Where, field: str, shape: tuple[int, ...], bound: float
           ) -> np.ndarray:
    """A list (of lists) of JSON numbers of ``shape``, each finite and within ``bound``."""
    def flat(v: Any, dims: tuple[int, ...], at: str) -> list:
        if not isinstance(v, list) or len(v) != dims[0]:
            raise w.fail(at, f"must be a list of {dims[0]}, found {_kind(v)}")
        if len(dims) == 1:
            bad = next((i for i, e in enumerate(v)
                        if isinstance(e, bool) or not isinstance(e, int | float)), None)
            if bad is not None:
                raise w.fail(f"{at}[{bad}]", f"must be a number, found {_kind(v[bad])}")
            return v
        return [e for i, row in enumerate(v) for e in flat(row, dims[1:], f"{at}[{i}]")]

    values = flat(x, shape, field)
    try:
        arr = np.asarray(values, dtype=float)
    except OverflowError:
        raise w.fail(field, "holds a number too large to be finite") from None
    bad = np.flatnonzero(~np.isfinite(arr) | (np.abs(arr) > bound))
    if len(bad):
        raise w.fail(field, f"must hold finite numbers of at most {bound:g} in size, "
                     f"found {values[int(bad[0])]!r}")
    return arr.reshape(shape)


def _pose(x: Any, w: _Where, field: str) -> np.ndarray:
    x = _object(x, w, field, {"position", "quaternion"}, {"position", "quaternion"})
    p = _array(x["position"], w, f"{field}.position", (3,), MAX_COORD)
    q = _array(x["quaternion"], w, f"{field}.quaternion", (4,), 2.0)
    if abs(float(np.linalg.norm(q)) - 1.0) > 1e-6:
        raise w.fail(f"{field}.quaternion", f"must be a unit quaternion, its length is "
                     f"{float(np.linalg.norm(q)):.6g}")
    return np.concatenate([p, q])


# --- the manifest -----------------------------------------------------------------------

def check_manifest(doc: Any, w: _Where) -> dict[str, Any]:
    """The manifest's fields, each checked (but not against the arm: :func:`read_folder`
    does that once the robot has loaded). Returns the values to build a sequence of, the
    parts as checked dicts with ``start``/``end`` poses as arrays."""
    from ..lang.descriptors import REGISTRY
    from ..lang.ir import State

    if isinstance(doc, dict) and doc.get("format") != _FORMAT:
        raise w.fail("format", f"is {doc.get('format')!r}, expected {_FORMAT!r}")
    doc = _object(doc, w, "", _MANIFEST_KEYS, _MANIFEST_NEEDS)
    out: dict[str, Any] = {"robot": _name(doc["robot"], w, "robot"),
                           "ee_frame": _name(doc["ee_frame"], w, "ee_frame", null=True),
                           "shiver_joint": _name(doc["shiver_joint"], w, "shiver_joint"),
                           "behaviour": _name(doc["behaviour"], w, "behaviour")}
    names = doc["joint_names"]
    if not isinstance(names, list) or not 1 <= len(names) <= 64:
        raise w.fail("joint_names", f"must be a list of 1 to 64 names, found {_kind(names)}")
    out["joint_names"] = tuple(_name(n, w, f"joint_names[{i}]") for i, n in enumerate(names))
    q = doc["q_start"]
    out["q_start"] = _array(q, w, "q_start", (len(names),), MAX_JOINT)
    state = doc["state"]
    if state is not None and (not isinstance(state, str)
                              or state not in {s.value for s in State}):
        raise w.fail("state", f"must be one of {', '.join(s.value for s in State)} or "
                     f"null, found {_kind(state) if not isinstance(state, str) else repr(state)}")
    out["state"] = state
    out["intensity"] = _number(doc["intensity"], w, "intensity", 0.0, 1.0)
    out["rate"] = rate = _number(doc["rate"], w, "rate", MIN_RATE, MAX_RATE)
    goal = _object(doc["goal"], w, "goal", {"position"}, {"position"})
    out["goal"] = _array(goal["position"], w, "goal.position", (3,), MAX_COORD)
    if "duration" in doc:
        _number(doc["duration"], w, "duration", 0.0, MAX_DURATION)
    if "quaternion_order" in doc and doc["quaternion_order"] != "w, x, y, z":
        raise w.fail("quaternion_order", f"must be 'w, x, y, z', found "
                     f"{doc['quaternion_order']!r}")
    if "parameters" in doc:
        params = doc["parameters"]
        if not isinstance(params, dict) or len(params) > 64 or not all(
                isinstance(v, str) and len(v) <= MAX_NAME for v in params.values()):
            raise w.fail("parameters", f"must be an object of texts, found {_kind(params)}")
    out["descriptors"] = _descriptors(doc["descriptors"], w, REGISTRY)
    parts = doc["parts"]
    if not isinstance(parts, list) or not parts:
        raise w.fail("parts", f"must be a non-empty list, found {_kind(parts)}")
    if len(parts) > MAX_PARTS:
        raise w.fail("parts", f"lists {len(parts)} parts, more than the {MAX_PARTS} a "
                     "sequence may have", code=D608)
    out["parts"] = [_entry(e, w, f"parts[{i}]") for i, e in enumerate(parts)]
    files = [e["file"] for e in out["parts"] if e["file"] is not None]
    seen: set[str] = set()
    for f in files:
        key = os.path.normpath(f) if isinstance(f, str) else f
        if key in seen:
            raise w.fail("parts", f"names the file `{f}` twice (each motion has its own "
                         "part file)", code=D608)
        seen.add(key)
    total = sum(e["duration"] for e in out["parts"])
    if total > MAX_DURATION:
        raise w.fail("parts", f"last {total:g} s in all, more than the {MAX_DURATION:g} s "
                     "a sequence may", code=D608)
    if total * rate > MAX_SAMPLES:
        raise w.fail("rate", f"{rate:g} Hz over {total:g} s is more than the "
                     f"{MAX_SAMPLES} samples a sequence may have", code=D608)
    start = out["parts"][0]["start"][:3]
    if float(np.linalg.norm(out["goal"] - start)) < MIN_GOAL_DISTANCE:
        raise w.fail("goal.position", "is the first part's start: the goal must differ "
                     "from where the motion starts")
    return out


def _descriptors(x: Any, w: _Where, registry: dict) -> dict[str, Any]:
    if not isinstance(x, dict):
        raise w.fail("descriptors", f"must be an object, found {_kind(x)}")
    out: dict[str, Any] = {}
    for name, v in x.items():
        at = f"descriptors.{name}"
        d = registry.get(name)
        if d is None:
            raise w.fail(at, f"is not a descriptor (expected {', '.join(registry)})")
        if v is None:
            out[name] = None
        else:
            if d.is_count:
                _number(v, w, at, 0.0, 1000.0, whole=True)
            else:
                _number(v, w, at, -1e6, 1e6)
            out[name] = v
    return out


def _entry(e: Any, w: _Where, field: str) -> dict[str, Any]:
    e = _object(e, w, field, _PART_KEYS, _PART_KEYS - {"lead"})
    kind = e["kind"]
    if kind not in _KINDS:
        shown = repr(kind) if isinstance(kind, str) else _kind(kind)
        raise w.fail(f"{field}.kind", f"must be one of {', '.join(_KINDS)}, found {shown}")
    out = {"kind": kind,
           "duration": _number(e["duration"], w, f"{field}.duration", 0.0, MAX_DURATION),
           "lead": _number(e.get("lead", 0.0), w, f"{field}.lead", -MAX_LEAD, MAX_LEAD),
           "start": _pose(e["start"], w, f"{field}.start"),
           "end": _pose(e["end"], w, f"{field}.end"), "file": e["file"]}
    if e["file"] is not None and kind in ("pause", "shiver"):
        raise w.fail(f"{field}.file", f"must be null for a {kind} (only a motion has a "
                     "part file)")
    if e["file"] is not None and not isinstance(e["file"], str):
        raise w.fail(f"{field}.file", f"must be a path or null, found {_kind(e['file'])}")
    values = e["values"]
    if not isinstance(values, dict) or len(values) > 16:
        raise w.fail(f"{field}.values", f"must be an object of at most 16 numbers, found "
                     f"{_kind(values)}")
    out["values"] = {str(k): _number(v, w, f"{field}.values.{k}", -1e6, 1e6)
                     for k, v in values.items()}
    if kind == "shiver":
        _shiver(out["values"], w, f"{field}.values")
    return out


def _shiver(values: dict[str, float], w: _Where, field: str) -> None:
    for key in ("amplitude", "frequency", "cycles"):
        if key not in values:
            raise w.fail(f"{field}.{key}", "is missing (a shiver needs its amplitude, "
                         "frequency and cycles)")
    _number(values["amplitude"], w, f"{field}.amplitude", 0.0, 360.0)
    f = _number(values["frequency"], w, f"{field}.frequency", 0.0, 100.0, above=True)
    c = _number(values["cycles"], w, f"{field}.cycles", 1.0, 100_000.0, whole=True)
    if c / f > MAX_DURATION:
        raise w.fail(f"{field}.cycles", f"{c:g} cycles at {f:g} Hz last more than the "
                     f"{MAX_DURATION:g} s a part may", code=D608)


# --- a part file ------------------------------------------------------------------------

def _class_of(x: dict, w: _Where, field: str, want: str) -> None:
    module, name = x.get("module"), x.get("class")
    named = (module, name) if isinstance(module, str) and isinstance(name, str) else None
    if named is None or ALLOWED.get(named) != want:
        shown = f"`{module}.{name}`" if isinstance(module, str) and isinstance(name, str) \
            and len(module) + len(name) < 200 else \
            f"module {_kind(module)}, class {_kind(name)}"
        at = f"{field}." if field else ""
        raise w.fail(f"{at}module", f"names {shown}: only movement_primitives' {want} is "
                     "built from a .dmp folder, and nothing named in a file is imported",
                     code=D607, hint="a part file is a CartesianDMP that `aouc compile "
                     "--format dmp` wrote")


def check_part(doc: Any, w: _Where) -> dict[str, Any]:
    """A part file's fields, each checked: the arguments :func:`build_dmp` needs."""
    if isinstance(doc, dict):  # what a file names is refused before anything else
        _class_of(doc, w, "", _CARTESIAN)
        for key in ("forcing_term_pos", "forcing_term_rot"):
            if isinstance(doc.get(key), dict):
                _class_of(doc[key], w, key, _TERM)
    doc = _object(doc, w, "", _DMP_KEYS, _DMP_NEEDS)
    et = _number(doc["_execution_time"], w, "_execution_time", 1e-3, MAX_EXECUTION_TIME)
    int_dt = _number(doc["int_dt"], w, "int_dt", MIN_INT_DT, MAX_INT_DT)
    if et / int_dt > MAX_STEPS:
        raise w.fail("int_dt", f"{et:g} s in steps of {int_dt:g} s is more than the "
                     f"{MAX_STEPS} integration steps a part may take", code=D608)
    n = int(_number(doc["n_weights_per_dim"], w, "n_weights_per_dim", 2, MAX_WEIGHTS,
                    whole=True))
    out: dict[str, Any] = {
        "execution_time": et, "int_dt": int_dt, "n_weights_per_dim": n,
        "dt": _number(doc["dt_"], w, "dt_", MIN_INT_DT, 1.0),
        "alpha_y": _array(doc["alpha_y"], w, "alpha_y", (6,), MAX_GAIN),
        "beta_y": _array(doc["beta_y"], w, "beta_y", (6,), MAX_GAIN),
        "start_y": _array(doc["start_y"], w, "start_y", (7,), MAX_COORD),
        "goal_y": _array(doc["goal_y"], w, "goal_y", (7,), MAX_COORD)}
    for gain in ("alpha_y", "beta_y"):
        if (out[gain] <= 0.0).any():
            raise w.fail(gain, "must hold numbers above 0")
    smooth = doc.get("smooth_scaling", False)
    if not isinstance(smooth, bool):
        raise w.fail("smooth_scaling", f"must be true or false, found {_kind(smooth)}")
    out["smooth_scaling"] = smooth
    for key, dims in (("n_dims", 7), ("n_vel_dims", 6)):
        if key in doc and (isinstance(doc[key], bool) or doc[key] != dims):
            raise w.fail(key, f"must be {dims} (a CartesianDMP's), found {_kind(doc[key])}")
    for key in ("t", "last_t"):
        if key in doc and not (key == "last_t" and doc[key] is None):
            _number(doc[key], w, key, -MAX_DURATION, MAX_DURATION)
    for key, size in (("start_yd", 6), ("start_ydd", 6), ("goal_yd", 6), ("goal_ydd", 6),
                      ("current_y", 7), ("current_yd", 6)):
        if key in doc:
            _array(doc[key], w, key, (size,), 1e6)
    if "initialized" in doc and not isinstance(doc["initialized"], bool):
        raise w.fail("initialized", f"must be true or false, found {_kind(doc['initialized'])}")
    for key in ("forcing_term_pos", "forcing_term_rot"):
        out[key] = _term(doc[key], w, key, n)
    return out


def _term(x: Any, w: _Where, field: str, n: int) -> np.ndarray:
    if isinstance(x, dict):
        _class_of(x, w, field, _TERM)
    x = _object(x, w, field, _TERM_KEYS, {"module", "class", "weights_"})
    for key in ("goal_t", "start_t", "overlap", "alpha_z", "log_overlap", "execution_time"):
        if key in x:
            _number(x[key], w, f"{field}.{key}", -1e6, 1e6)
    if "n_weights_per_dim" in x and (isinstance(x["n_weights_per_dim"], bool)
                                     or x["n_weights_per_dim"] != n):
        raise w.fail(f"{field}.n_weights_per_dim", f"must be the DMP's {n}, found "
                     f"{_kind(x['n_weights_per_dim'])}")
    for key in ("centers", "widths"):
        if key in x:
            _array(x[key], w, f"{field}.{key}", (n,), math.inf if key == "widths" else 1e6)
    return _array(x["weights_"], w, f"{field}.weights_", (3, n), 1e12)


def build_dmp(args: dict[str, Any]) -> Any:
    """The ``CartesianDMP`` of checked arguments (:func:`check_part`): constructed, its
    weights copied in, configured to its start and goal. The only class built."""
    from movement_primitives.dmp import CartesianDMP

    dmp = CartesianDMP(execution_time=args["execution_time"], dt=args["dt"],
                       n_weights_per_dim=args["n_weights_per_dim"], int_dt=args["int_dt"],
                       smooth_scaling=args["smooth_scaling"], alpha_y=args["alpha_y"],
                       beta_y=args["beta_y"])
    dmp.forcing_term_pos.weights_ = args["forcing_term_pos"].copy()
    dmp.forcing_term_rot.weights_ = args["forcing_term_rot"].copy()
    dmp.configure(start_y=args["start_y"], goal_y=args["goal_y"])
    return dmp


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
    w = _Where(shown)
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
        pw = _Where(os.path.join(path, e["file"]))
        doc["files"].append(pw.path)
        raw = _read_bounded(name, pw.path, min(MAX_PART_BYTES, budget), w, field)
        budget -= len(raw)
        checked.append(check_part(_json(raw, pw), pw))
    for args in checked:
        dmps.append(None if args is None else build_dmp(args))
    return doc, dmps


def _check_arm(doc: dict[str, Any], w: _Where) -> None:
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
