"""The ``.dmp`` format: a folder that ``movement_primitives`` reads part by part.

``x.dmp/`` holds ``manifest.json`` (``"format": "aou-dmp/1"``: the robot, the goal, the
start configuration, the descriptors, and one entry per part with its kind, duration,
end poses and values) and one file per motion, ``parts/NN-KIND.json``, written by
``movement_primitives.io.write_json``, so that ``movement_primitives.io.read_json``
loads it as a ``CartesianDMP``. The folder is made beside its target under a temporary
name and renamed onto it when complete; an existing ``.dmp`` folder there is replaced,
anything else is refused (I502).
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from typing import Any

import numpy as np

from ..core.codes import D602, I502
from ..core.diagnostics import AouError, Span, diag
from .export import MOVES, DmpPart, DmpSequence

__all__ = ["FORMAT", "PARAMETERS", "manifest", "read_dmp", "write_dmp"]

FORMAT = "aou-dmp/1"

#: Which DMP parameter controls each descriptor (docs/dmp.md, the scaling rules).
#: By the descriptor's kind and episode key ("" for a count).
PARAMETERS = {
    ("approach", "peak_acceleration"): "execution_time_ of each approach (peak ~ amplitude "
                                       "/ time^2); forcing weights scaled with the amplitude",
    ("retreat", "peak_acceleration"): "execution_time_ of each retreat, as above",
    ("retreat", "distance"): "start_y/goal_y and forcing weights (amplitude scaling)",
    ("pause", "duration"): "the hold's duration",
    ("pause", ""): "the parts (fixed)",
    ("retreat", ""): "the parts (fixed)",
    ("gaze", "horizontal"): "rotation of start_y/goal_y and weights about the goal (kept)",
    ("gaze", "vertical"): "rotation of start_y/goal_y and weights about the goal (kept)",
    ("tilt", "angle"): "the orientation goal_y (kept)",
    ("tilt", "velocity"): "execution_time_ of each tilt",
    ("shiver", "amplitude"): "the oscillation's amplitude",
}


def _where(path: str) -> Span:
    return Span.whole_file(path)


def manifest(seq: DmpSequence) -> dict[str, Any]:
    """The manifest document of ``seq`` (files named as :func:`write_dmp` names them)."""
    parts = []
    for k, p in enumerate(seq.parts, 1):
        parts.append({
            "kind": p.kind, "duration": p.duration,
            "file": f"parts/{k:02d}-{p.kind}.json" if p.dmp is not None else None,
            "start": {"position": p.start[:3].tolist(), "quaternion": p.start[3:].tolist()},
            "end": {"position": p.end[:3].tolist(), "quaternion": p.end[3:].tolist()},
            "lead": p.lead, "values": p.values})
    return {"format": FORMAT, "behaviour": seq.behaviour, "state": seq.state,
            "intensity": seq.intensity, "robot": seq.robot, "ee_frame": seq.ee_frame,
            "joint_names": list(seq.joint_names), "goal": {"position": list(seq.goal)},
            "q_start": seq.q_start.tolist(), "shiver_joint": seq.shiver_joint,
            "rate": seq.rate, "duration": seq.duration, "quaternion_order": "w, x, y, z",
            "descriptors": seq.descriptors, "parameters": _parameters(), "parts": parts}


def _parameters() -> dict[str, str]:
    from ..synth.recipe import descriptor

    return {descriptor(kind, key).name: text for (kind, key), text in PARAMETERS.items()}


def write_dmp(path: str, seq: DmpSequence, *, inputs: Any = ()) -> None:
    """Write ``seq`` as the folder ``path`` (see the module's docstring).

    Raises:
        AouError: I502 when it cannot be written, is an input, or would replace
            something that is not a ``.dmp`` folder.
    """
    from movement_primitives.io import write_json

    final = os.path.abspath(path)
    if any(os.path.exists(i) and os.path.realpath(i) == os.path.realpath(final)
           for i in inputs):
        raise AouError(diag(I502, f"refusing to overwrite the input `{path}`", _where(path)))
    if os.path.lexists(final) and not os.path.isfile(os.path.join(final, "manifest.json")):
        raise AouError(diag(I502, f"cannot write `{path}`: it exists and is not a .dmp "
                            "folder", _where(path), hint="choose another output with -o"))
    parent = os.path.dirname(final)
    try:
        os.makedirs(parent, exist_ok=True)
        tmp = tempfile.mkdtemp(prefix=".aouc-", dir=parent)
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}",
                            _where(path))) from None
    try:
        doc = manifest(seq)
        os.mkdir(os.path.join(tmp, "parts"))
        for p, entry in zip(seq.parts, doc["parts"], strict=True):
            if entry["file"] is not None:
                write_json(os.path.join(tmp, entry["file"]), p.dmp)
        with open(os.path.join(tmp, "manifest.json"), "w", encoding="utf-8") as fh:
            json.dump(doc, fh, indent=1)
            fh.write("\n")
        os.chmod(tmp, 0o755)
        if os.path.lexists(final):
            old = tempfile.mkdtemp(prefix=".aouc-old-", dir=parent)
            os.rename(final, os.path.join(old, "x"))
            os.rename(tmp, final)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.rename(tmp, final)
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}",
                            _where(path))) from None
    finally:
        if os.path.exists(tmp):
            shutil.rmtree(tmp, ignore_errors=True)


def _bad(path: str, what: str) -> AouError:
    return AouError(diag(D602, f"`{path}` is not a readable .dmp folder: {what}",
                         _where(path), hint="write one with `aouc compile FILE --format dmp`"))


def read_dmp(path: str) -> DmpSequence:
    """The sequence written at ``path``.

    Raises:
        AouError: I501 when the folder or its manifest cannot be read; D602 when they are
            not an ``aou-dmp/1`` sequence.
    """
    from ..core.files import read_text

    text = read_text(os.path.join(path, "manifest.json"), "the .dmp manifest")
    try:
        doc = json.loads(text)
        if doc.get("format") != FORMAT:
            raise _bad(path, f"its format is {doc.get('format')!r}, expected {FORMAT!r}")
        parts = [_part(path, e) for e in doc["parts"]]
        return DmpSequence(
            doc["robot"], doc["ee_frame"], tuple(doc["joint_names"]),
            tuple(float(x) for x in doc["goal"]["position"]),  # type: ignore[arg-type]
            np.asarray(doc["q_start"], dtype=float), doc["shiver_joint"], float(doc["rate"]),
            doc["behaviour"], doc["state"], float(doc["intensity"]), doc["descriptors"],
            parts)
    except AouError:
        raise
    except (ValueError, KeyError, TypeError, IndexError) as exc:
        raise _bad(path, f"{type(exc).__name__}: {exc}") from None


def _part(path: str, e: dict) -> DmpPart:
    from movement_primitives.io import read_json

    def pose(x: dict) -> np.ndarray:
        return np.asarray([*x["position"], *x["quaternion"]], dtype=float)

    dmp = None
    if e["kind"] in MOVES and e["file"] is not None:
        name = os.path.join(path, e["file"])
        if not os.path.isfile(name):
            raise _bad(path, f"its part `{e['file']}` is missing")
        dmp = read_json(name)
    return DmpPart(e["kind"], float(e["duration"]), pose(e["start"]), pose(e["end"]), dmp,
                   {k: float(v) for k, v in e["values"].items()}, float(e.get("lead", 0.0)))
