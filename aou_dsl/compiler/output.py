"""Stage 8, output: the trajectory file, written atomically and deterministically.

Five formats: ``json`` (``aou-trajectory/1``), ``csv`` (``t`` then one column per joint),
``npz`` (numpy arrays plus the JSON header), and for ROS 2 (:mod:`.ros`) ``mcap`` (a bag
folder holding one ``trajectory_msgs/msg/JointTrajectory``) and ``yaml`` (that message
as YAML). Floats are written with Python's shortest round-trip representation (up to 17
significant digits). Nothing that varies between runs (times, paths, dates) is written,
so the same input and versions give the same bytes. A file is written to a temporary
name beside the target and renamed over it only when complete
(:func:`aou_dsl.core.files.write_atomic`; a bag: a temporary folder, renamed): on any error no
output appears and an existing file is untouched.
"""

from __future__ import annotations

import io
import json
import os
import zipfile

import numpy as np

from ..core.codes import I502
from ..core.diagnostics import AouError, Span, diag
from ..core.files import write_atomic
from ..version import __version__
from .ros import is_bag

__all__ = ["FORMATS", "SAMPLE_KEYS", "document_header", "encode", "output_paths",
           "trajectory_document", "with_samples", "write_atomic",
           "write_output"]

FORMATS = ("json", "csv", "npz", "mcap", "yaml", "dmp")
#: Formats whose output is a folder (a ROS 2 bag; DMPs, aou_dsl.dmp), not a file.
FOLDER_FORMATS = ("mcap", "dmp")


#: The keys of a trajectory document that hold its samples, one list entry per sample.
SAMPLE_KEYS = ("t", "q", "qd", "qdd")


def trajectory_document(result, *, measured: dict, declared: dict, cv: dict,
                        checks: dict | None = None, rate: float) -> dict:
    """The trajectory document (``aou-trajectory/1``) of a
    :class:`~.pipeline.CompileResult`."""
    return with_samples(document_header(result, measured=measured, declared=declared, cv=cv,
                                        checks=checks, rate=rate), result.trajectory)


def with_samples(header: dict, tr) -> dict:
    """The document ``header`` (:func:`document_header`) completed with the samples of
    the trajectory ``tr`` as lists (:data:`SAMPLE_KEYS`, last)."""
    import gc

    # Hundreds of thousands of floats in lists, which cannot form cycles: the garbage
    # collector, left on, would walk everything the process holds many times over.
    collecting = gc.isenabled()
    gc.disable()
    try:
        return header | {k: getattr(tr, k).tolist() for k in SAMPLE_KEYS}
    finally:
        if collecting:
            gc.enable()


def _robot_keys(tr) -> dict:
    """What another tool needs to recompute the hand pose from the file: where the
    end-effector frame is, and which robot (its URDF's path and SHA-256)."""
    from ..robot.identity import frame_definition, robot_identity
    from ..robot.load import load_robot

    loaded = load_robot(tr.robot, tr.package_dirs)
    frame = tr.ee_definition or frame_definition(loaded.spec)
    return {"ee_frame_definition": frame.to_json(),
            "robot_identity": robot_identity(tr.robot, loaded)}


def document_header(result, *, measured: dict, declared: dict, cv: dict,
                    checks: dict | None = None, rate: float) -> dict:
    """The trajectory document of a :class:`~.pipeline.CompileResult` but its samples."""
    tr = result.trajectory
    b = result.behaviour
    return {
        "format": "aou-trajectory/1",
        "generator": f"aouc {__version__}",
        "behaviour": b.name,
        "state": b.state.value if b.state else None,
        "robot": tr.robot,
        "ee_frame": tr.ee_frame,
        **_robot_keys(tr),
        "joint_names": list(tr.joint_names),
        "goal": {"position": list(tr.goal)},
        "rate": rate,
        "duration": tr.duration,
        "descriptors": {"declared": _clean(declared), "measured": measured},
        "cv": cv,
        "episodes": [{"kind": k, "t_start": a, "t_end": e} for k, a, e in tr.episodes],
        "checks": checks or {},
    }


def _clean(declared: dict) -> dict:
    """Declared values as written: a unit's round trip (6 deg to radians and back gives
    6.000000000000001) rounded off at 12 significant digits; counts stay whole."""
    return {k: float(f"{v:.12g}") if isinstance(v, float) else v
            for k, v in declared.items()}


def encode(doc: dict, fmt: str) -> bytes:
    """The bytes of ``doc`` in ``fmt`` (a file format: ``mcap`` is a folder, written by
    :func:`write_output`)."""
    if fmt == "json":
        return (json.dumps(doc, separators=(",", ":")) + "\n").encode()
    if fmt == "csv":
        # Comment lines carry what a CSV has no column for; readers skip `#` lines.
        goal = ",".join(repr(float(x)) for x in doc["goal"]["position"])
        lines = [f"# format: {doc['format']}", f"# robot: {doc['robot']}",
                 f"# ee_frame: {doc['ee_frame']}", f"# goal: {goal}"]
        lines += [f"# {k}: {json.dumps(doc[k], separators=(',', ':'))}"
                  for k in ("ee_frame_definition", "robot_identity") if k in doc]
        lines.append(",".join(["t", *doc["joint_names"]]))
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
    if fmt == "yaml":
        from .ros import encode_yaml

        return encode_yaml(doc)
    if fmt in FOLDER_FORMATS:
        raise AouError(diag(I502, f"`{fmt}` output is a folder (a ROS 2 bag), not bytes: "
                            "write it with write_output", Span.whole_file("<output>")))
    raise AouError(diag(I502, f"unknown output format `{fmt}`: expected one of "
                        f"{', '.join(FORMATS)}", Span.whole_file("<output>")))


def write_output(path: str, doc: dict, fmt: str, *, inputs: list[str] | tuple = ()) -> None:
    """Write ``doc`` in ``fmt`` at ``path`` (a file, or for ``mcap`` a bag folder),
    atomically and never over one of ``inputs``.

    Raises:
        AouError: I502 when it cannot be written.
    """
    if fmt == "dmp":  # the command line writes DMPs (aou_dsl/cli/dmp_cmd.py)
        raise ValueError("DMPs are written by aou_dsl.cli.dmp_cmd.write_compiled")
    if fmt in FOLDER_FORMATS:
        from .ros import write_bag

        write_bag(doc, path, inputs=inputs)
    else:
        write_atomic(path, encode(doc, fmt), inputs=inputs)


def output_paths(inputs: list[tuple[str, str | None]], output: str | None, fmt: str | None
                 ) -> tuple[list[str], str]:
    """Where each input's trajectory goes, and the format.

    One input: ``-o FILE`` (its extension sets the format unless ``fmt`` does), ``-o DIR``
    or the current folder. Several inputs: ``-o`` is a folder (default: the current one);
    files found in a folder keep their path below it, so ``x/same.aou`` and
    ``y/same.aou`` never land on one output.

    A ROS 2 bag (``mcap``) is a folder named without the extension: ``-o x.mcap`` writes
    the bag ``x/`` (holding ``x.mcap`` and ``metadata.yaml``); an existing bag folder given
    as ``-o`` is that output, not a folder of outputs.

    Raises:
        AouError: I502 for an unknown format, ``-o FILE`` with several inputs, or two
            inputs that would write the same output.
    """
    many = len(inputs) > 1 or any(root is not None for _, root in inputs)
    is_dir = output is not None and (output.endswith(os.sep) or (
        os.path.isdir(output) and not is_bag(output) and not output.endswith(".dmp")))
    if fmt is None:
        ext = os.path.splitext(output or "")[1].lstrip(".")
        fmt = ext if output and not many and not is_dir and ext else "json"
    if fmt not in FORMATS:
        raise AouError(diag(I502, f"unknown output format `{fmt}`: expected one of "
                            f"{', '.join(FORMATS)}", Span.whole_file(output or fmt)))
    if many and output and not is_dir and os.path.splitext(output)[1]:
        raise AouError(diag(I502, f"several inputs need -o to be a folder, found "
                            f"`{output}`", Span.whole_file(output)))
    folder = output if (many or is_dir) else None
    suffix = "" if fmt == "mcap" else f".{fmt}"
    dests = []
    for src, root in inputs:
        rel = os.path.relpath(src, root) if root is not None else os.path.basename(src)
        name = os.path.splitext(rel)[0] + suffix
        if folder is not None:
            dests.append(os.path.join(folder, name))
        elif output and fmt in FOLDER_FORMATS:
            dests.append(output[:-len(".mcap")] if output.endswith(".mcap") else output)
        else:
            dests.append(output or name)
    seen: dict[str, str] = {}
    for (src, _), dest in zip(inputs, dests, strict=True):
        key = os.path.realpath(dest)
        if key in seen:
            raise AouError(diag(I502, f"`{seen[key]}` and `{src}` would both be written to "
                                f"`{dest}`", Span.whole_file(src),
                                hint="compile them into different folders with -o"))
        seen[key] = src
    return dests, fmt
