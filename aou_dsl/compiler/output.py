"""Stage 8, output: the trajectory file, written atomically and deterministically.

Five formats: ``json`` (``aou-trajectory/1``), ``csv`` (``t`` then one column per joint;
with ``--csv-derivatives``, :data:`CSV_DERIVATIVES`, a velocity then an acceleration
column per joint after them),
``npz`` (numpy arrays plus the JSON header), and for ROS 2 (:mod:`.ros`) ``mcap`` (a bag
folder holding one ``trajectory_msgs/msg/JointTrajectory``) and ``yaml`` (that message
as YAML). Nothing that varies between runs (times, paths, dates) is written, so the same
input and versions give the same bytes. A file is written to a temporary name beside the
target and renamed over it only when complete (:func:`aou_dsl.core.files.write_atomic`; a
bag: a temporary folder, renamed): on any error no output appears and an existing file
is untouched.

JSON and CSV text is written by orjson when it is installed (the optional extra
``fastjson``; it writes a document's arrays straight from NumPy's buffers, some fifty
times faster than the standard module through lists), else by the standard ``json``
module, made to write the same bytes (:func:`json_bytes`). Either way a float is its
shortest round-trip decimal (up to 17 significant digits: it reads back as the same
float), written as orjson writes it: ``0.00001`` and ``1.5e-7`` where Python's ``repr``
gives ``1e-05`` and ``1.5e-07``, otherwise as ``repr``. Text is UTF-8 (not ``\\u``
escapes), and a value that is not a number (NaN, an infinity) is ``null``.
"""

from __future__ import annotations

import importlib
import io
import json
import os
import re
import zipfile
from bisect import bisect_right
from itertools import chain
from types import ModuleType

import numpy as np

from ..core.codes import I502
from ..core.diagnostics import AouError, Span, diag
from ..core.files import write_atomic
from ..version import __version__
from .ros import is_bag


def _optional(name: str) -> ModuleType | None:
    """The optional extra ``name`` (``fastjson``: orjson), or None when not installed."""
    try:
        return importlib.import_module(name)  # safe: a fixed name, never a file's
    except ImportError:  # pragma: no cover - installed with the tests
        return None


orjson = _optional("orjson")

__all__ = ["CSV_DERIVATIVES", "FORMATS", "SAMPLE_KEYS", "array_document", "document_header",
           "encode", "json_bytes", "output_paths", "trajectory_document", "with_samples",
           "write_atomic", "write_output"]

FORMATS = ("json", "csv", "npz", "mcap", "yaml", "dmp")
#: Formats whose output is a folder (a ROS 2 bag; DMPs, aou_dsl.dmp), not a file.
FOLDER_FORMATS = ("mcap", "dmp")
#: The encoding of ``--format csv --csv-derivatives``: the CSV's columns (``t``, one per
#: joint), then ``qd_JOINT`` per joint, then ``qdd_JOINT`` per joint. Not a format of its
#: own (the file is a ``.csv``); a reader of the plain CSV that takes the columns it
#: knows by name reads the positions the same.
CSV_DERIVATIVES = "csv+derivatives"


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


def array_document(header: dict, tr) -> dict:
    """The document ``header`` completed with the samples of ``tr`` as the trajectory's
    float arrays (:data:`SAMPLE_KEYS`, last), not lists: what :func:`encode` writes
    fastest, the same bytes as from :func:`with_samples`'s lists."""
    return header | {k: np.ascontiguousarray(getattr(tr, k), dtype=np.float64)
                     for k in SAMPLE_KEYS}


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


#: What orjson writes for these floats when it writes them as the fallback does (orjson
#: 3.11.7 and later). An orjson that writes them otherwise is not used, so that the bytes
#: of a document never depend on which encoder is installed.
_PROBE = ([1e-05, 1.5e-07, 1e-10, 1e16, 0.0001, -0.0, 2.5, 1e308],
          b"[0.00001,1.5e-7,1e-10,1e+16,0.0001,-0.0,2.5,1e+308]")
_FAST = orjson is not None and orjson.dumps(_PROBE[0]) == _PROBE[1]
#: A JSON string (the standard module's: quotes inside are escaped).
_STRING = re.compile(r'"(?:[^"\\]|\\.)*"')
#: The exponent of a float Python writes from ``1e-05`` to ``9.9e-09`` (``repr`` writes
#: exponents from -1 to -4 as plain decimals, and -10 on as orjson does).
_EXPONENT = re.compile(r"e-0[5-9]")


def _orjson_number(text: str) -> str:
    """A float ``repr`` writes ``1.5e-05`` or ``1.5e-07`` as orjson writes it:
    ``0.000015``, ``1.5e-7``."""
    sign = "-" if text.startswith("-") else ""
    mantissa, exponent = text.lstrip("-").split("e-0")
    if exponent == "5":
        return f"{sign}0.0000{mantissa.replace('.', '')}"
    return f"{sign}{mantissa}e-{exponent}"


def _orjson_floats(text: str, *, strings: bool = True) -> str:
    """Text of the standard module (or of ``repr``) with its floats as orjson writes
    them; a JSON string in it (when ``strings``) stays as it is. Such floats are few (a
    motion's tiny velocities at rest), so each is found by its exponent, then its digits
    to the left."""
    hits = [m.start() for m in _EXPONENT.finditer(text)]
    if not hits:
        return text
    spans = [m.span() for m in _STRING.finditer(text)] if strings else []
    starts = [a for a, _ in spans]
    out, last = [], 0
    for i in hits:
        k = bisect_right(starts, i) - 1
        if k >= 0 and i < spans[k][1]:
            continue  # inside a string
        j = i
        while j > 0 and (text[j - 1] in "0123456789."):
            j -= 1
        if j > 0 and text[j - 1] == "-":
            j -= 1
        out += [text[last:j], _orjson_number(text[j:i + 4])]
        last = i + 4
    out.append(text[last:])
    return "".join(out)


def _plain(value: object) -> object:
    """NumPy arrays and scalars as lists and Python numbers (for the standard module);
    a float that is not a number as None (``null``, as orjson writes it)."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray | np.generic):
        return _plain(value.tolist())
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def _as_list(value: object) -> object:
    if isinstance(value, np.ndarray | np.generic):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def _std_json(doc: object) -> str:
    """``doc`` as compact JSON text by the standard module, floats as orjson writes them."""
    try:
        text = json.dumps(doc, separators=(",", ":"), ensure_ascii=False, allow_nan=False,
                          default=_as_list)
    except ValueError:  # a NaN or an infinity somewhere: null, as orjson writes it
        text = json.dumps(_plain(doc), separators=(",", ":"), ensure_ascii=False)
    return _orjson_floats(text)


_PLAIN = frozenset((float, int, str, bool, type(None)))


def _orjson_writes_as_lists(value: object) -> bool:
    """Whether orjson writes every NumPy value in ``value`` as the standard module
    writes its ``tolist()``: float64, integer and boolean ones do; a float32 it writes
    as the shortest float32 (``0.1``), where its list holds the float64 of it
    (``0.10000000149011612``)."""
    if type(value) in _PLAIN:
        return True
    if isinstance(value, np.ndarray):
        return value.dtype.kind in "biu" or value.dtype == np.float64
    if isinstance(value, np.generic):
        return not isinstance(value, np.floating) or isinstance(value, np.float64)
    if isinstance(value, dict):
        return all(map(_orjson_writes_as_lists, value.values()))
    if isinstance(value, list | tuple):  # lists (of lists) of plain values: at C speed
        kinds = set(map(type, value))
        if kinds <= _PLAIN or (kinds == {list} and _PLAIN.issuperset(
                map(type, chain.from_iterable(value)))):
            return True
        return all(map(_orjson_writes_as_lists, value))
    return True


def json_bytes(doc: object, *, newline: bool = True) -> bytes:
    """``doc`` (dicts, lists, strings, numbers, None; NumPy arrays and scalars) as
    compact JSON in UTF-8, with a final newline unless ``newline`` is False: by orjson
    when it is installed (and writes floats as expected), else by the standard module,
    the same bytes either way. A lone surrogate in a string (a file name that is not
    UTF-8) is written as its ``\\u`` escape."""
    if _FAST and orjson is not None and _orjson_writes_as_lists(doc):
        option = orjson.OPT_SERIALIZE_NUMPY | (orjson.OPT_APPEND_NEWLINE if newline else 0)
        try:
            return orjson.dumps(doc, option=option)
        except (orjson.JSONEncodeError, TypeError):
            pass  # a lone surrogate, a key that is no string: the standard module's way
    text = _std_json(doc) + ("\n" if newline else "")
    return text.encode("utf-8", "backslashreplace")


def _float_text(x: float) -> str:
    """One float as :func:`json_bytes` writes it (``nan`` for a NaN: a CSV has no null)."""
    return _orjson_floats(repr(float(x)), strings=False)


def _csv_rows(t: np.ndarray, q: np.ndarray) -> bytes:
    """``t`` then the joints of each sample, a line each, floats as in the JSON."""
    table = np.ascontiguousarray(np.column_stack([t, q]), dtype=np.float64)
    if len(table) == 0:
        return b""
    if _FAST and orjson is not None and np.isfinite(table).all():
        # [[a,b],[c,d]] -> a,b\nc,d: orjson writes every float; the rest is punctuation
        return orjson.dumps(table, option=orjson.OPT_SERIALIZE_NUMPY)[2:-2].replace(
            b"],[", b"\n") + b"\n"
    text = "\n".join(",".join(map(repr, row)) for row in table.tolist()) + "\n"
    return _orjson_floats(text, strings=False).encode()


def encode(doc: dict, fmt: str) -> bytes:
    """The bytes of ``doc`` in ``fmt`` (a file format: ``mcap`` is a folder, written by
    :func:`write_output`). The samples may be lists or float arrays
    (:func:`array_document`): the bytes are the same."""
    if fmt == "json":
        return json_bytes(doc)
    if fmt in ("csv", CSV_DERIVATIVES):
        # Comment lines carry what a CSV has no column for; readers skip `#` lines.
        goal = ",".join(_float_text(x) for x in doc["goal"]["position"])
        lines = [f"# format: {doc['format']}", f"# robot: {doc['robot']}",
                 f"# ee_frame: {doc['ee_frame']}", f"# goal: {goal}"]
        lines += [f"# {k}: {json_bytes(doc[k], newline=False).decode()}"
                  for k in ("ee_frame_definition", "robot_identity") if k in doc]
        names = list(doc["joint_names"])
        more = ([f"qd_{n}" for n in names] + [f"qdd_{n}" for n in names]
                if fmt == CSV_DERIVATIVES else [])
        lines.append(",".join(["t", *names, *more]))
        head = ("\n".join(lines) + "\n").encode("utf-8", "backslashreplace")
        t = np.asarray(doc["t"], dtype=np.float64)
        q = np.asarray(doc["q"], dtype=np.float64).reshape(len(t), -1)
        if more:
            q = np.column_stack([q, *(np.asarray(doc[k], dtype=np.float64).reshape(len(t), -1)
                                      for k in ("qd", "qdd"))])
        return head + _csv_rows(t, q)
    if fmt == "npz":
        buf = io.BytesIO()
        header = {k: v for k, v in doc.items() if k not in SAMPLE_KEYS}
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
            for key in SAMPLE_KEYS:
                arr = io.BytesIO()
                np.lib.format.write_array(arr, np.asarray(doc[key], dtype=np.float64))
                # A fixed date keeps the archive byte-identical between runs. (A member
                # given as a ZipInfo is stored, not deflated: it is written at the speed
                # of copying.)
                zf.writestr(zipfile.ZipInfo(f"{key}.npy", (1980, 1, 1, 0, 0, 0)),
                            arr.getvalue())
            zf.writestr(zipfile.ZipInfo("header.json", (1980, 1, 1, 0, 0, 0)),
                        json.dumps(header, indent=1, default=_as_list))
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
