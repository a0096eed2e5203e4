"""``aouc compile --format dmp`` and ``aouc dmp roll``: the command line's side of the DMPs.

Thin: the parser of ``aouc dmp``, the command, and the writer ``aouc compile`` calls for
``--format dmp`` (a trajectory document -> a ``.dmp`` folder).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

__all__ = ["cmd_dmp", "rolled_document", "trajectory_of", "write_compiled", "write_document"]


def trajectory_of(doc: dict, path: str = "<document>") -> Any:
    """The :class:`~aou_dsl.core.trajectory.Trajectory` of a trajectory document."""
    import numpy as np

    from ..core.trajectory import Trajectory

    arr = {k: np.asarray(doc[k], dtype=float) for k in ("t", "q", "qd", "qdd")}
    return Trajectory(arr["t"], arr["q"], tuple(doc["joint_names"]), doc["robot"],
                      doc.get("ee_frame"), tuple(doc["goal"]["position"]), arr["qd"],
                      arr["qdd"], tuple((e["kind"], e["t_start"], e["t_end"])
                                        for e in doc.get("episodes", [])), path,
                      doc.get("behaviour", ""))


def write_document(path: str, doc: dict, *, inputs: Any = ()) -> None:
    """``--format dmp``: the sequence of the compiled document ``doc``, written at ``path``."""
    from ..dmp.export import to_dmp
    from ..dmp.manifest import write_dmp

    state = doc.get("state") or (doc.get("cv") or {}).get("state")
    seq = to_dmp(trajectory_of(doc, path), behaviour=doc.get("behaviour"), state=state,
                 descriptors=(doc.get("descriptors") or {}).get("measured"))
    write_dmp(path, seq, inputs=inputs)


def rolled_document(seq: Any, solved: Any) -> dict:
    """The trajectory document (``aou-trajectory/1``) of a solved rollout; its
    ``descriptors.declared`` are what the scaling rules predict."""
    from ..version import __version__

    tr, ro, m = solved.trajectory, solved.rollout, solved.measured
    return {
        "format": "aou-trajectory/1", "generator": f"aouc {__version__}",
        "behaviour": seq.behaviour, "state": seq.state, "robot": tr.robot,
        "ee_frame": tr.ee_frame, "joint_names": list(tr.joint_names),
        "goal": {"position": list(tr.goal)}, "rate": seq.rate, "duration": tr.duration,
        "descriptors": {"declared": ro.predicted, "measured": m.descriptors.to_json()},
        "cv": m.cv.to_json(),
        "episodes": [{"kind": k, "t_start": a, "t_end": e} for k, a, e in tr.episodes],
        "dmp": {"time_scale": ro.time_scale, "intensity": ro.intensity, "scale": ro.scale,
                "pinned": list(ro.pinned)},
        "checks": {"kinematic": {"ok": all(c.ok for c in solved.checks)}},
        "t": tr.t.tolist(), "q": tr.q.tolist(), "qd": tr.qd.tolist(), "qdd": tr.qdd.tolist()}


def cmd_dmp(args: argparse.Namespace) -> int:
    """``aouc dmp roll``: 0 when the rollout passes, 1 when it is refused."""
    import os

    from ..compiler.output import encode
    from ..core.files import check_output, write_atomic
    from ..dmp.manifest import read_dmp
    from ..dmp.solve import solve
    from ..synth.recipe import descriptor
    from .args import EXIT_ERRORS, EXIT_OK
    from .report import format_text

    fmt = os.path.splitext(args.output or "")[1].lstrip(".") or "json"
    if args.output and fmt not in ("json", "csv", "npz"):
        print(f"aouc: error: cannot write `{args.output}`: expected .json, .csv or .npz",
              file=sys.stderr)
        return 2
    reads = _reads(args.path)
    if args.output:  # before any work: the output rule, against the folder read
        check_output(args.output, reads=reads)
        _outside(args.output, args.path)
    seq = read_dmp(args.path)
    reads = _reads(args.path, seq)
    out = solve(seq, path=args.path, check=not args.no_check, goal=args.goal,
                time_scale=args.time_scale, intensity=args.intensity,
                pinned=tuple(descriptor(kind, "peak_acceleration").name for kind in args.pin))
    for d in out.diagnostics:
        print(format_text(d), file=sys.stderr)
    if not out.ok or out.measured is None:
        print(f"{args.path}: refused, nothing written", file=sys.stderr)
        return EXIT_ERRORS
    m = out.measured.descriptors
    print(f"{'descriptor':<24}{'rule predicts':>16}{'measured':>16}")
    for name, want in out.rollout.predicted.items():
        print(f"{name:<24}{_num(want):>16}{_num(m[name]):>16}")
    if args.output:
        write_atomic(args.output, encode(rolled_document(seq, out), fmt), inputs=reads)
        print(f"wrote {args.output}: {out.trajectory.duration:.2f} s of motion",
              file=sys.stderr)
    return EXIT_OK


def _reads(path: str, seq: Any = None) -> list[str]:
    """The files ``aouc dmp roll`` reads from the folder ``path``: the folder and its
    manifest, and (once read) every part file."""
    import os

    return [path, os.path.join(path, "manifest.json"), *(seq.files if seq else ())]


def _outside(output: str, folder: str) -> None:
    """The output rule for a folder read: nothing is written inside it (I502)."""
    import os

    from ..core.codes import I502
    from ..core.diagnostics import AouError, Span, diag

    real = os.path.realpath(folder)
    if os.path.realpath(output).startswith(real + os.sep):
        raise AouError(diag(I502, f"refusing to write `{output}`: it is inside `{folder}`, "
                            "the .dmp folder this command reads", Span.whole_file(output),
                            hint="choose another output with -o", input=folder))


def _num(v: Any) -> str:
    return "-" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))


def write_compiled(path: str, res: Any, fmt: str, inputs: Any = ()) -> None:
    """Write a build's output: DMPs for ``dmp`` (this layer knows them), else as
    :func:`~aou_dsl.driver.parallel.write_result` writes every other format."""
    if fmt == "dmp":
        write_document(path, res.document, inputs=inputs)
        return
    from ..driver.parallel import write_result

    write_result(path, res, fmt, inputs=inputs)
