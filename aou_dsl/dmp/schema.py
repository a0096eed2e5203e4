"""The checks of a ``.dmp`` folder's documents, field by field, and the one class built
from them (:mod:`.reader` reads the files; docs/dmp.md, "A .dmp folder is untrusted
input").

Every field has a type, a range and a size, and every number is finite; a field the
format does not have is refused. A part file must name ``CartesianDMP`` (its forcing
terms ``ForcingTerm``, :data:`ALLOWED`): the object is constructed from the checked
arguments and the checked weights are copied in (:func:`build_dmp`); nothing named in a
file is imported. A failure is D602 naming the file and the field, D607 for a class
outside the allow-list, D608 for a count or duration beyond its bound.
"""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from ..core.codes import D602, D607, D608
from ..core.diagnostics import AouError, Span, diag
from .allowed import (
    MAX_COORD,
    MAX_DURATION,
    MAX_EXECUTION_TIME,
    MAX_GAIN,
    MAX_INT_DT,
    MAX_JOINT,
    MAX_LEAD,
    MAX_NAME,
    MAX_PARTS,
    MAX_RATE,
    MAX_SAMPLES,
    MAX_STEPS,
    MAX_WEIGHTS,
    MIN_GOAL_DISTANCE,
    MIN_INT_DT,
    MIN_RATE,
)
from .parts import Shape, dmp_kinds

__all__ = ["ALLOWED", "Where", "build_dmp", "check_manifest", "check_part", "kind_of"]

_CARTESIAN = "CartesianDMP"
_TERM = "ForcingTerm"
#: The ``(module, class)`` pairs a part may name, and what each is. Nothing else is
#: built; nothing named in a file is imported.
ALLOWED = {("movement_primitives.dmp._cartesian_dmp", _CARTESIAN): _CARTESIAN,
           ("movement_primitives.dmp", _CARTESIAN): _CARTESIAN,
           ("movement_primitives.dmp._forcing_term", _TERM): _TERM}

_FORMAT = "aou-dmp/1"
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


class Where:
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


def kind_of(x: Any) -> str:
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


# --- checking values --------------------------------------------------------------------

def _object(x: Any, w: Where, field: str, keys: set[str], needs: set[str]) -> dict:
    if not isinstance(x, dict):
        raise w.fail(field, f"must be an object, found {kind_of(x)}")
    extra = sorted(set(x) - keys)
    if extra:
        at = f"{field}." if field else ""
        raise w.fail(f"{at}{extra[0]}", "is not a field of the format")
    missing = sorted(needs - set(x))
    if missing:
        at = f"{field}." if field else ""
        raise w.fail(f"{at}{missing[0]}", "is missing")
    return x


def _number(x: Any, w: Where, field: str, lo: float, hi: float, *,
            above: bool = False, whole: bool = False) -> float:
    """``x`` as a float: a JSON number (not a boolean), finite, in ``[lo, hi]`` (``(lo,
    hi]`` when ``above``), an integer when ``whole``."""
    if isinstance(x, bool) or not isinstance(x, int | float):
        raise w.fail(field, f"must be a number, found {kind_of(x)}")
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


def _name(x: Any, w: Where, field: str, *, null: bool = False) -> str | None:
    if x is None and null:
        return None
    if not isinstance(x, str) or not x or len(x) > MAX_NAME or "\0" in x:
        what = "a name" + (" or null" if null else "")
        raise w.fail(field, f"must be {what}, found {kind_of(x)}")
    return x


def _array(x: Any, w: Where, field: str, shape: tuple[int, ...], bound: float
           ) -> np.ndarray:
    """A list (of lists) of JSON numbers of ``shape``, each finite and within ``bound``."""
    def flat(v: Any, dims: tuple[int, ...], at: str) -> list:
        if not isinstance(v, list) or len(v) != dims[0]:
            raise w.fail(at, f"must be a list of {dims[0]}, found {kind_of(v)}")
        if len(dims) == 1:
            bad = next((i for i, e in enumerate(v)
                        if isinstance(e, bool) or not isinstance(e, int | float)), None)
            if bad is not None:
                raise w.fail(f"{at}[{bad}]", f"must be a number, found {kind_of(v[bad])}")
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


def _pose(x: Any, w: Where, field: str) -> np.ndarray:
    x = _object(x, w, field, {"position", "quaternion"}, {"position", "quaternion"})
    p = _array(x["position"], w, f"{field}.position", (3,), MAX_COORD)
    q = _array(x["quaternion"], w, f"{field}.quaternion", (4,), 2.0)
    if abs(float(np.linalg.norm(q)) - 1.0) > 1e-6:
        raise w.fail(f"{field}.quaternion", f"must be a unit quaternion, its length is "
                     f"{float(np.linalg.norm(q)):.6g}")
    return np.concatenate([p, q])


# --- the manifest -----------------------------------------------------------------------

def check_manifest(doc: Any, w: Where) -> dict[str, Any]:
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
        raise w.fail("joint_names", f"must be a list of 1 to 64 names, found {kind_of(names)}")
    out["joint_names"] = tuple(_name(n, w, f"joint_names[{i}]") for i, n in enumerate(names))
    q = doc["q_start"]
    out["q_start"] = _array(q, w, "q_start", (len(names),), MAX_JOINT)
    state = doc["state"]
    if state is not None and (not isinstance(state, str)
                              or state not in {s.value for s in State}):
        raise w.fail("state", f"must be one of {', '.join(s.value for s in State)} or "
                     f"null, found {kind_of(state) if not isinstance(state, str) else repr(state)}")
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
            raise w.fail("parameters", f"must be an object of texts, found {kind_of(params)}")
    out["descriptors"] = _descriptors(doc["descriptors"], w, REGISTRY)
    parts = doc["parts"]
    if not isinstance(parts, list) or not parts:
        raise w.fail("parts", f"must be a non-empty list, found {kind_of(parts)}")
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


def _descriptors(x: Any, w: Where, registry: dict) -> dict[str, Any]:
    if not isinstance(x, dict):
        raise w.fail("descriptors", f"must be an object, found {kind_of(x)}")
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


def _entry(e: Any, w: Where, field: str) -> dict[str, Any]:
    e = _object(e, w, field, _PART_KEYS, _PART_KEYS - {"lead"})
    kind = e["kind"]
    kinds = dmp_kinds()  # looked up by name: nothing named in a file is imported
    if not isinstance(kind, str) or kind not in kinds:
        shown = repr(kind) if isinstance(kind, str) else kind_of(kind)
        raise w.fail(f"{field}.kind", f"must be one of {', '.join(kinds)}, found {shown}")
    shape = kinds[kind].shape
    out = {"kind": kind,
           "duration": _number(e["duration"], w, f"{field}.duration", 0.0, MAX_DURATION),
           "lead": _number(e.get("lead", 0.0), w, f"{field}.lead", -MAX_LEAD, MAX_LEAD),
           "start": _pose(e["start"], w, f"{field}.start"),
           "end": _pose(e["end"], w, f"{field}.end"), "file": e["file"]}
    if e["file"] is not None and shape is not Shape.MOVE:
        raise w.fail(f"{field}.file", f"must be null for a {kind} (only a motion has a "
                     "part file)")
    if e["file"] is not None and not isinstance(e["file"], str):
        raise w.fail(f"{field}.file", f"must be a path or null, found {kind_of(e['file'])}")
    values = e["values"]
    if not isinstance(values, dict) or len(values) > 16:
        raise w.fail(f"{field}.values", f"must be an object of at most 16 numbers, found "
                     f"{kind_of(values)}")
    out["values"] = {str(k): _number(v, w, f"{field}.values.{k}", -1e6, 1e6)
                     for k, v in values.items()}
    if shape is Shape.OSCILLATION:
        _shiver(out["values"], w, f"{field}.values")
    return out


def _shiver(values: dict[str, float], w: Where, field: str) -> None:
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

def _class_of(x: dict, w: Where, field: str, want: str) -> None:
    module, name = x.get("module"), x.get("class")
    named = (module, name) if isinstance(module, str) and isinstance(name, str) else None
    if named is None or ALLOWED.get(named) != want:
        shown = f"`{module}.{name}`" if isinstance(module, str) and isinstance(name, str) \
            and len(module) + len(name) < 200 else \
            f"module {kind_of(module)}, class {kind_of(name)}"
        at = f"{field}." if field else ""
        raise w.fail(f"{at}module", f"names {shown}: only movement_primitives' {want} is "
                     "built from a .dmp folder, and nothing named in a file is imported",
                     code=D607, hint="a part file is a CartesianDMP that `aouc compile "
                     "--format dmp` wrote")


def check_part(doc: Any, w: Where) -> dict[str, Any]:
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
        raise w.fail("smooth_scaling", f"must be true or false, found {kind_of(smooth)}")
    out["smooth_scaling"] = smooth
    for key, dims in (("n_dims", 7), ("n_vel_dims", 6)):
        if key in doc and (isinstance(doc[key], bool) or doc[key] != dims):
            raise w.fail(key, f"must be {dims} (a CartesianDMP's), found {kind_of(doc[key])}")
    for key in ("t", "last_t"):
        if key in doc and not (key == "last_t" and doc[key] is None):
            _number(doc[key], w, key, -MAX_DURATION, MAX_DURATION)
    for key, size in (("start_yd", 6), ("start_ydd", 6), ("goal_yd", 6), ("goal_ydd", 6),
                      ("current_y", 7), ("current_yd", 6)):
        if key in doc:
            _array(doc[key], w, key, (size,), 1e6)
    if "initialized" in doc and not isinstance(doc["initialized"], bool):
        raise w.fail("initialized", f"must be true or false, found {kind_of(doc['initialized'])}")
    for key in ("forcing_term_pos", "forcing_term_rot"):
        out[key] = _term(doc[key], w, key, n)
    return out


def _term(x: Any, w: Where, field: str, n: int) -> np.ndarray:
    if isinstance(x, dict):
        _class_of(x, w, field, _TERM)
    x = _object(x, w, field, _TERM_KEYS, {"module", "class", "weights_"})
    for key in ("goal_t", "start_t", "overlap", "alpha_z", "log_overlap", "execution_time"):
        if key in x:
            _number(x[key], w, f"{field}.{key}", -1e6, 1e6)
    if "n_weights_per_dim" in x and (isinstance(x["n_weights_per_dim"], bool)
                                     or x["n_weights_per_dim"] != n):
        raise w.fail(f"{field}.n_weights_per_dim", f"must be the DMP's {n}, found "
                     f"{kind_of(x['n_weights_per_dim'])}")
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
