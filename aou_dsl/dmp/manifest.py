"""The ``.dmp`` format: a folder of ``movement_primitives`` DMPs, one file per part.

``x.dmp/`` holds ``manifest.json`` (``"format": "aou-dmp/1"``: the robot, the goal, the
start configuration, the descriptors, and one entry per part with its kind, duration,
end poses and values) and one file per motion, ``parts/NN-KIND.json``, written by
``movement_primitives.io.write_json``. aou reads it back with its own checked reader
(:mod:`.reader`), never with the library's ``read_json``, which imports and calls
whatever module and class a file names. The folder is made beside its target under a
temporary name and renamed onto it when complete; an existing ``.dmp`` folder there is
replaced, anything else is refused (I502).
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from typing import Any

from ..core.codes import I502
from ..core.diagnostics import AouError, Span, diag
from .export import DmpPart, DmpSequence

__all__ = ["FORMAT", "manifest", "read_dmp", "write_dmp"]

FORMAT = "aou-dmp/1"


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
    """Which DMP parameter controls each descriptor (docs/dmp.md, the scaling rules): the
    registry's lines (:func:`.parts.parameter_lines`), by descriptor name."""
    from ..synth.recipe import descriptor
    from .parts import parameter_lines

    return {descriptor(kind, key).name: text for (kind, key), text in parameter_lines()}


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


def read_dmp(path: str) -> DmpSequence:
    """The sequence written at ``path``, read as untrusted input by aou's own
    schema-checked reader (:mod:`.reader`: the folder closed, every field checked, only
    ``CartesianDMP`` built; ``movement_primitives.io.read_json`` is never called).

    Raises:
        AouError: I501 when the folder or a file cannot be read; D602 when they are not
            an ``aou-dmp/1`` sequence (naming the field), D607 for a part naming a class
            outside the allow-list, D608 for a folder that is not closed.
    """
    from .reader import read_folder

    doc, dmps = read_folder(path)
    parts = [DmpPart(e["kind"], e["duration"], e["start"], e["end"], dmp, e["values"],
                     e["lead"]) for e, dmp in zip(doc["parts"], dmps, strict=True)]
    return DmpSequence(
        doc["robot"], doc["ee_frame"], doc["joint_names"],
        tuple(float(x) for x in doc["goal"]),  # type: ignore[arg-type]
        doc["q_start"], doc["shiver_joint"], doc["rate"], doc["behaviour"], doc["state"],
        doc["intensity"], doc["descriptors"], parts, tuple(doc["files"]))
