"""Stage 8, output: the trajectory file (LANGUAGE.md), written atomically and deterministically.

Three formats: ``json`` (``aou-trajectory/1``), ``csv`` (``t`` then one column per joint)
and ``npz`` (numpy arrays plus the JSON header). Floats are written with Python's
shortest round-trip representation (up to 17 significant digits). Nothing that varies
between runs (times, paths, dates) is written, so the same input and versions give the
same bytes. A file is written to a temporary name beside the target and renamed over it
only when complete: on any error no output appears and an existing file is untouched.
"""

from __future__ import annotations

import io
import json
import os
import tempfile
import zipfile
from collections.abc import Sequence

import numpy as np

from .. import __version__
from ..diagnostics import AouError, Span, diag

__all__ = ["FORMATS", "trajectory_document", "write_atomic", "encode"]

FORMATS = ("json", "csv", "npz")


def trajectory_document(result, *, measured: dict, declared: dict, cv: dict,
                        checks: dict | None = None, rate: float) -> dict:
    """The JSON document of LANGUAGE.md for a :class:`~.pipeline.CompileResult`."""
    tr = result.trajectory
    b = result.behaviour
    return {
        "format": "aou-trajectory/1",
        "generator": f"aouc {__version__}",
        "behaviour": b.name,
        "state": b.state.value if b.state else None,
        "robot": tr.robot,
        "ee_frame": tr.ee_frame,
        "joint_names": list(tr.joint_names),
        "goal": {"position": list(tr.goal)},
        "rate": rate,
        "duration": tr.duration,
        "descriptors": {"declared": declared, "measured": measured},
        "cv": cv,
        "episodes": [{"kind": k, "t_start": a, "t_end": e} for k, a, e in tr.episodes],
        "checks": checks or {},
        "t": tr.t.tolist(),
        "q": tr.q.tolist(),
        "qd": tr.qd.tolist(),
        "qdd": tr.qdd.tolist(),
    }


def encode(doc: dict, fmt: str) -> bytes:
    """The bytes of ``doc`` in ``fmt``."""
    if fmt == "json":
        return (json.dumps(doc, separators=(",", ":")) + "\n").encode()
    if fmt == "csv":
        lines = [",".join(["t", *doc["joint_names"]])]
        lines += [",".join(repr(v) for v in [t, *row]) for t, row in zip(doc["t"], doc["q"],
                                                                           strict=True)]
        return ("\n".join(lines) + "\n").encode()
    if fmt == "npz":
        buf = io.BytesIO()
        header = {k: v for k, v in doc.items() if k not in ("t", "q", "qd", "qdd")}
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
            for key in ("t", "q", "qd", "qdd"):
                arr = io.BytesIO()
                np.lib.format.write_array(arr, np.asarray(doc[key], dtype=np.float64))
                # A fixed date keeps the archive byte-identical between runs.
                zf.writestr(zipfile.ZipInfo(f"{key}.npy", (1980, 1, 1, 0, 0, 0)),
                            arr.getvalue())
            zf.writestr(zipfile.ZipInfo("header.json", (1980, 1, 1, 0, 0, 0)),
                        json.dumps(header, indent=1))
        return buf.getvalue()
    raise ValueError(f"unknown format {fmt!r}")


def write_atomic(path: str, data: bytes, *, inputs: Sequence[str] = ()) -> None:
    """Write ``data`` to ``path`` atomically; never over one of ``inputs``.

    Raises:
        AouError: I502 when the file cannot be written or would overwrite an input.
    """
    where = Span.whole_file(path)
    target = os.path.realpath(path)
    if any(os.path.exists(i) and os.path.realpath(i) == target for i in inputs):
        raise AouError(diag("I502", f"refusing to overwrite the input `{path}`", where,
                            hint="choose another output with -o"))
    folder = os.path.dirname(target) or "."
    try:
        fd, tmp = tempfile.mkstemp(prefix=".aouc-", suffix=".tmp", dir=folder)
    except OSError as exc:
        raise AouError(diag("I502", f"cannot write `{path}`: {exc.strerror}", where)) from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, target)
    except OSError as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise AouError(diag("I502", f"cannot write `{path}`: {exc.strerror}", where)) from None
