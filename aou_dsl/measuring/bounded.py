"""The parsing steps of reading a recording that a hostile file could make crash, hang or
take the machine's memory, each bounded and each failure an R-diagnostic:

- :func:`parse_json`: a document nested too deeply, or holding a number of thousands of
  digits, is R401 (not a RecursionError);
- :func:`csv_table`: a field longer than the csv module's limit (an unclosed quote reads
  the rest of the file as one field) is R401 at its row; more rows than
  :func:`~aou_dsl.core.inputs.max_samples` is R410; the rows become numbers a chunk at a time;
- :func:`npz_members`: only stored or deflated members that are not encrypted; each
  ``.npy`` header read on its own (its size bounded), the shape it claims checked against
  the samples bound and against the bytes that are there, before an array is made;
- :func:`numbers`: samples that are numbers (not booleans, texts or dates), as floats.
"""

from __future__ import annotations

import csv
import io
import json
import tokenize
import zipfile
from typing import Any

import numpy as np

from ..core.codes import R401, R410
from ..core.diagnostics import AouError, Span, diag
from ..core.inputs import max_samples, size_text, too_many_samples

__all__ = ["MAX_JOINT_VALUE", "csv_table", "npz_members", "numbers", "parse_json"]

#: Largest joint position [rad or m, or deg before its unit is known] read as one: a
#: value beyond is no joint position in any unit (1e308 at every sample is not a pose).
MAX_JOINT_VALUE = 1e4
#: Zip compression methods Python reads: stored, deflated, bzip2, LZMA.
_METHODS = {zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED, zipfile.ZIP_BZIP2, zipfile.ZIP_LZMA}
_ARRAYS = ("t", "q", "qd", "qdd")


def _bad(path: str, message: str, span: Span | None = None, hint: str | None = None
         ) -> AouError:
    return AouError(diag(R401, message, span or Span.whole_file(path), hint=hint))


def parse_json(path: str, text: str) -> Any:
    """The JSON document ``text``.

    Raises:
        AouError: R401 for text that is not JSON, nested too deeply, or holding an
            integer too long to read.
    """
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise AouError(diag(R401, f"not valid JSON: {exc.msg}",
                            Span.point(path, exc.lineno, exc.colno))) from None
    except RecursionError:
        raise _bad(path, "not a trajectory: the JSON is nested too deeply (arrays in "
                   "arrays, thousands deep)") from None
    except ValueError as exc:  # an integer past Python's int-string limit
        raise _bad(path, f"not a trajectory: a number in the JSON cannot be read ({exc})"
                   .split(";")[0]) from None


#: Rows converted to numbers at once: the cells of a chunk are strings only meanwhile.
_CHUNK = 20_000


def csv_table(path: str, lines: list[str]
              ) -> tuple[tuple[int, list[str]], np.ndarray, np.ndarray]:
    """The header row of a CSV (its line, its cells), the line of each sample and the
    samples as numbers, shape (N, columns). Comment rows (``#``) are skipped. The rows are
    converted a chunk at a time, so that a long recording is held as numbers, not as
    millions of strings.

    Raises:
        AouError: R401 for an empty file, a row of another width or a cell that is no
            number (at its row), and at the row whose field is longer than the csv
            module reads; R410 when there are more rows than the samples bound.
    """
    bound = max_samples()
    reader = csv.reader(lines)
    header: tuple[int, list[str]] | None = None
    at: list[int] = []
    chunks: list[np.ndarray] = []
    chunk: list[list[str]] = []
    try:
        for r in reader:
            if not r or r[0].startswith("#"):
                continue
            if header is None:
                header = (reader.line_num, [h.strip() for h in r])
                continue
            if len(r) != len(header[1]):
                line = reader.line_num
                raise _bad(path, f"row {line} has {len(r)} columns; the header has "
                           f"{len(header[1])}", span=Span.point(path, line, 1))
            at.append(reader.line_num)
            chunk.append(r)
            if len(at) > bound:
                raise too_many_samples(path, f"more than {bound:,}")  # rows, so far
            if len(chunk) == _CHUNK:
                chunks.append(_floats(path, chunk, at[-len(chunk):], header[1], lines))
                chunk = []
    except csv.Error as exc:
        line = reader.line_num
        raise _bad(path, f"row {line}: {exc}; a field this long is no number (is a quote "
                   "left open?)", span=Span.point(path, line, 1)) from None
    if header is None:
        raise _bad(path, "the CSV file is empty")
    if chunk:
        chunks.append(_floats(path, chunk, at[-len(chunk):], header[1], lines))
    values = np.vstack(chunks) if chunks else np.zeros((0, len(header[1])))
    return header, np.asarray(at, dtype=np.int64), values


def _floats(path: str, rows: list[list[str]], at: list[int], header: list[str],
            lines: list[str]) -> np.ndarray:
    """The cells of ``rows`` (at lines ``at``) as numbers; R401 at the first that is
    none."""
    try:
        return np.array(rows, dtype=float)
    except ValueError:
        pass
    for line, r in zip(at, rows, strict=True):
        for j, cell in enumerate(r):
            try:
                float(cell)
            except ValueError:
                col = 1 if '"' in lines[line - 1] else len(",".join(r[:j] + [""])) + 1
                raise _bad(path, f"row {line}, column `{header[j]}`: `{cell}` is not a "
                           "number", span=Span.point(path, line, col)) from None
    raise _bad(path, "a row holds a value that is not a number")  # not reached


def numbers(values: Any) -> np.ndarray | None:
    """``values`` (a list of numbers, or of lists of them) as floats, or None when one
    of them is not a number (the caller names it). Booleans and texts are no numbers."""
    try:
        arr = np.asarray(values)
    except (ValueError, TypeError):
        return None
    if arr.dtype.kind not in "iuf":
        return None
    try:
        return arr.astype(float)
    except (ValueError, TypeError, OverflowError):
        return None


def _member_info(path: str, zf: zipfile.ZipFile, name: str) -> zipfile.ZipInfo:
    info = zf.getinfo(name)
    if info.flag_bits & 0x1:
        raise _bad(path, f"not an aou NPZ trajectory: `{name}` is encrypted",
                   hint="aou writes NPZ files unencrypted (np.savez); save it again "
                        "without a password")
    if info.compress_type not in _METHODS:
        raise _bad(path, f"not an aou NPZ trajectory: `{name}` is compressed with a method "
                   f"aou does not read (zip method {info.compress_type}: deflate64, AES or "
                   "another)", hint="save it with np.savez or np.savez_compressed")
    return info


def _read_member(path: str, zf: zipfile.ZipFile, name: str, limit: int) -> bytes:
    info = _member_info(path, zf, name)
    if info.file_size > limit:
        raise _too_large(path, name, size_text(info.file_size), limit)
    with zf.open(info) as fh:
        data = fh.read(limit + 1)
    if len(data) > limit:
        raise _too_large(path, name, f"more than {size_text(limit)}", limit)
    return data


def _too_large(path: str, name: str, size: str, limit: int) -> AouError:
    from ..core.inputs import ENV_BYTES

    return AouError(diag(R410, f"`{name}` in `{path}` unpacks to {size}; aou reads at "
                         f"most {size_text(limit)} of a trajectory", Span.whole_file(path),
                         hint=f"if the file is right, raise the bound: set {ENV_BYTES} (in "
                              "MB)", limit=limit, variable=ENV_BYTES))


def _npy(path: str, name: str, data: bytes, joints: int) -> np.ndarray:
    """The array of an ``.npy`` member, after checking the shape its header claims."""
    fmt = np.lib.format
    fh = io.BytesIO(data)
    try:
        version = fmt.read_magic(fh)
        read_header = fmt.read_array_header_2_0 if version >= (2, 0) else \
            fmt.read_array_header_1_0
        shape, fortran, dtype = read_header(fh)
    except (ValueError, SyntaxError, RecursionError, MemoryError, TypeError, KeyError,
            IndexError, tokenize.TokenError) as exc:  # numpy parses the header as Python
        raise _bad(path, f"not an aou NPZ trajectory: `{name}` has no header numpy reads "
                   f"({str(exc)[:80]})") from None
    if dtype.kind not in "iuf" or dtype.hasobject:
        raise _bad(path, f"`{name}` holds {dtype} values; expected numbers (float64)")
    n = shape[0] if shape else 1
    if n > max_samples():
        raise too_many_samples(path, n, f" (so says the header of `{name}`)")
    count = int(np.prod(shape, dtype=np.int64)) if shape else 1
    if count > max_samples() * max(joints, 1) or count * dtype.itemsize > len(data):
        raise _bad(path, f"`{name}` claims shape {shape} of {dtype}, more than the "
                   f"{len(data)} bytes it holds")
    body = np.frombuffer(data, dtype, count, fh.tell())
    return (body.reshape(shape[::-1]).T if fortran else body.reshape(shape)).copy()


def npz_members(path: str, data: bytes, limit: int) -> tuple[Any, dict[str, np.ndarray]]:
    """The header document and the arrays (``t``, ``q``, ``qd``, ``qdd``) of an NPZ.

    Raises:
        AouError: R401 for a file that is no NPZ aou reads; R410 for members larger than
            ``limit`` bytes or arrays of more samples than the bound.
    """
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            names = zf.namelist()
            if "header.json" not in names:
                raise _bad(path, "not an aou NPZ trajectory: `header.json` is missing",
                           hint="an NPZ of aou holds t.npy, q.npy and header.json")
            text = _read_member(path, zf, "header.json", limit).decode("utf-8", "replace")
            doc = parse_json(path, text)
            joints = len(doc.get("joint_names") or ()) if isinstance(doc, dict) else 0
            arrays = {k: _npy(path, f"{k}.npy", _read_member(path, zf, f"{k}.npy", limit),
                              min(joints, 1000))
                      for k in _ARRAYS if f"{k}.npy" in names}
    except (zipfile.BadZipFile, zipfile.LargeZipFile, NotImplementedError, RuntimeError,
            EOFError, OSError, ValueError) as exc:
        raise _bad(path, f"not an aou NPZ trajectory: {exc}",
                   hint="an NPZ of aou holds t.npy, q.npy and header.json") from None
    return doc, arrays
