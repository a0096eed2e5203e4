"""Answers kept by other platforms: JATOS result archives and Qualtrics-style exports.

A JATOS results archive (``.jrzip`` or ``.zip``, JATOS's "Export Results") holds one
folder per study result and, inside it, one per component result:
``study_result_N/comp-result_M/data.txt`` is what the component submitted (aou's page
submits its rows as a JSON array), ``.../files/`` what it uploaded, and ``metadata.json``
the results' dates and states. Only the ``data.txt`` members are read, in the order of
their result ids, never extracted to disk: the archive is untrusted, so its member
count, every member's name (no absolute path, no ``..``) and the declared and read size
of every member read are bounded (E703 naming the member).

A Qualtrics-style CSV export (one row per respondent, under two or three header rows:
the column ids, the question texts, the ImportId JSON) is read through a mapping file
that says which column holds what (docs/study.md); each respondent becomes aou's rows,
with an end row only when the progress is 100 and the respondent finished.
"""

from __future__ import annotations

import csv
import io
import json
import re
import tomllib
import zipfile
import zlib

from ..core.codes import E703
from ..core.diagnostics import AouError, Span, diag
from ..core.inputs import read_input_text
from .spec import PART_B_OPTIONS, Study

__all__ = ["is_zip", "jatos_data", "qualtrics_rows", "read_mapping"]

#: The most members of a results archive.
MAX_MEMBERS = 100_000
#: The most bytes of one ``data.txt``, and of all of them together.
MAX_MEMBER = 64 * 2**20
MAX_TOTAL = 512 * 2**20
DATA = re.compile(r"study_result_(\d{1,18})/comp-result_(\d{1,18})/data\.txt")
ZIP_ERRORS = (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, NotImplementedError,
              RuntimeError, EOFError, OSError, ValueError)


def _bad(where: str, message: str) -> AouError:
    file = where.split("#")[0].split("!/")[0]
    return AouError(diag(E703, f"{where}: {message}", Span.whole_file(file)))


def is_zip(raw: bytes) -> bool:
    """Whether ``raw`` starts as a zip archive does (or an empty one)."""
    return raw[:4] in (b"PK\x03\x04", b"PK\x05\x06")


def _safe_name(path: str, name: str) -> None:
    parts = name.split("/")
    if (name.startswith(("/", "\\")) or re.match(r"[A-Za-z]:", name) or "\\" in name
            or "\0" in name or ".." in parts):
        raise _bad(path, f"member `{name[:200]}` is not a safe relative name (an absolute "
                   "path, `..` or a backslash): the archive is refused")


def jatos_data(raw: bytes, path: str) -> list[tuple[str, object]]:
    """Each ``data.txt`` of a JATOS results archive as ``(source, JSON)``, by result id;
    an empty ``data.txt`` (a component that submitted nothing) is skipped."""
    try:
        zf = zipfile.ZipFile(io.BytesIO(raw))
    except ZIP_ERRORS as exc:
        raise _bad(path, f"not a readable zip archive ({exc})") from None
    with zf:
        infos = zf.infolist()
        if len(infos) > MAX_MEMBERS:
            raise _bad(path, f"more than {MAX_MEMBERS} members")
        found = []
        total = 0
        for info in infos:
            _safe_name(path, info.filename)
            m = re.fullmatch(r"(?:[^/]+/)?" + DATA.pattern, info.filename)
            if m is None or info.is_dir():
                continue
            where = f"{path}!/{info.filename}"
            total += info.file_size
            if info.file_size > MAX_MEMBER or total > MAX_TOTAL:
                raise _bad(where, f"declares {info.file_size:,} bytes; aou reads at most "
                           f"{MAX_MEMBER:,} per member and {MAX_TOTAL:,} in all")
            found.append(((int(m[1]), int(m[2])), info, where))
        if not found:
            raise _bad(path, "a zip archive without a JATOS result "
                       "(study_result_N/comp-result_M/data.txt)")
        found.sort(key=lambda f: f[0])
        out: list[tuple[str, object]] = []
        for _, info, where in found:
            try:
                with zf.open(info) as fh:
                    data = fh.read(info.file_size + 1)
            except ZIP_ERRORS as exc:
                raise _bad(where, f"cannot be read ({exc})") from None
            if len(data) > info.file_size:
                raise _bad(where, "holds more than the size it declares")
            try:
                text = data.decode("utf-8-sig")
            except UnicodeDecodeError:
                raise _bad(where, "not UTF-8 text") from None
            if not text.strip():
                continue
            try:
                out.append((where, json.loads(text)))
            except ValueError as exc:
                raise _bad(where, f"not JSON (aou's page submits a JSON array of rows): "
                           f"{exc}") from None
        return out


# -- Qualtrics-style exports -----------------------------------------------------------

SIDES = ("low", "high")
ANSWERS = (*PART_B_OPTIONS, "left", "right")
#: The keys of a mapping file: the columns, the label tables, the questions.
COLUMNS = {"participant": "ResponseId", "progress": "Progress", "finished": "Finished"}
LABELS = ("states", "intensity", "answers", "sides")
QUESTIONS = {"part_a": ("state", "intensity", "description", "other_text"),
             "part_b": ("answer", "left"), "attention": ("answer",)}


def read_mapping(path: str, study: Study) -> dict:
    """A mapping file, checked against the study (E703 naming the key)."""
    text = read_input_text(path, "study")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise _bad(path, f"not TOML: {exc}") from None

    def fail(key: str, message: str) -> AouError:
        return _bad(path, f"`{key}`: {message}")

    unknown = sorted(set(data) - set(COLUMNS) - set(LABELS) - set(QUESTIONS))
    if unknown:
        raise fail(unknown[0], "not a key of a mapping file (participant, progress, "
                   "finished, [states], [intensity], [answers], [sides], [part_a.ID], "
                   "[part_b.ID], [attention.ID])")
    out: dict = {"columns": {}, "explicit": set(data) & set(COLUMNS)}
    for key, default in COLUMNS.items():
        v = data.get(key, default)
        if not isinstance(v, str) or not v:
            raise fail(key, "expected a column id")
        out["columns"][key] = v
    allowed = {"states": study.options, "answers": ANSWERS, "sides": SIDES}
    for key in LABELS:
        table = data.get(key, {})
        if not isinstance(table, dict):
            raise fail(key, "expected a table of labels")
        for label, value in table.items():
            ok = (isinstance(value, int) and not isinstance(value, bool)
                  and 1 <= value <= study.intensity) if key == "intensity" else \
                value in allowed[key]
            if not ok:
                want = f"a point 1..{study.intensity}" if key == "intensity" else \
                    ", ".join(allowed[key])
                raise fail(f"{key}.{label}", f"{str(value)[:40]!r} is not {want}")
        out[key] = dict(table)
    ids = {"part_a": [s.id for s in study.part_a], "part_b": [p.id for p in study.pairs],
           "attention": [f"C{i}" for i in range(1, len(study.attention) + 1)]}
    for part, fields in QUESTIONS.items():
        tables = data.get(part, {})
        if not isinstance(tables, dict):
            raise fail(part, f"expected [{part}.ID] tables")
        for qid, table in tables.items():
            if qid not in ids[part]:
                raise fail(f"{part}.{qid}", f"the study has no such question "
                           f"({', '.join(ids[part]) or 'none'})")
            if not isinstance(table, dict) or set(table) - set(fields) or \
                    not all(isinstance(v, str) and v for v in table.values()) or \
                    fields[0] not in table:
                raise fail(f"{part}.{qid}", f"expected column ids of {', '.join(fields)} "
                           f"(`{fields[0]}` needed)")
        missing = [q for q in ids[part] if q not in tables]
        if missing:
            raise fail(part, f"no column given for {', '.join(missing)}: every question "
                       "of the study needs one")
        out[part] = {q: tables[q] for q in ids[part]}
    return out


def _number(value: str, where: str, column: str) -> float:
    try:
        return float(value)
    except ValueError:
        raise _bad(where, f"column `{column}`: {value[:40]!r} is not a number") from None


def _is_number(value: str) -> bool:
    try:
        float(value)
    except ValueError:
        return False
    return True


def _label(table: dict, value: str, allowed, where: str, column: str, kind: str):
    v = value.strip()
    if v in table:
        return table[v]
    if v in allowed:
        return v
    raise _bad(where, f"column `{column}`: {v[:60]!r} is not a label of [{kind}] in the "
               f"mapping, nor one of {', '.join(map(str, allowed))}")


def _respondent(rec: dict, m: dict, study: Study, where: str) -> list[dict]:
    cols = m["columns"]
    pid = rec.get(cols["participant"], "").strip()
    if not pid:
        raise _bad(where, f"column `{cols['participant']}`: no participant id")
    rows: list[dict] = []
    for qid, c in m["part_a"].items():
        state = rec.get(c["state"], "").strip()
        if not state:
            continue
        row = {"participant": pid, "aou_part": "A", "aou_item": qid,
               "state": _label(m["states"], state, study.options, where, c["state"],
                               "states")}
        if "intensity" in c and rec.get(c["intensity"], "").strip():
            k = _label(m["intensity"], rec[c["intensity"]],
                       [str(i) for i in range(1, study.intensity + 1)], where,
                       c["intensity"], "intensity")
            row["intensity"] = int(k)
        for f in ("description", "other_text"):
            if f in c:
                row[f] = rec.get(c[f], "")
        rows.append(row)
    for qid, c in m["part_b"].items():
        raw = rec.get(c["answer"], "").strip()
        if not raw:
            continue
        answer = _label(m["answers"], raw, ANSWERS, where, c["answer"], "answers")
        left = rec.get(c["left"], "").strip() if "left" in c else ""
        left = _label(m["sides"], left, SIDES, where, c["left"], "sides") if left else None
        if answer in ("left", "right"):
            if left is None:
                raise _bad(where, f"column `{c['answer']}`: the answer names a side, and "
                           "the mapping gives no `left` column that says which variant "
                           "was there")
            answer = left if answer == "left" else ("high" if left == "low" else "low")
        rows.append({"participant": pid, "aou_part": "B", "aou_item": qid,
                     "answer": answer, "left": left})
    for qid, c in m["attention"].items():
        got = rec.get(c["answer"], "").strip()
        if got:
            check = study.attention[int(qid[1:]) - 1]
            rows.append({"participant": pid, "aou_part": "attention", "aou_item": qid,
                         "passed": got == check["answer"]})
    progress = _number(rec.get(cols["progress"], ""), where, cols["progress"])
    finished = rec.get(cols["finished"], "true").strip().lower()
    if finished not in ("true", "false", "1", "0"):
        raise _bad(where, f"column `{cols['finished']}`: {finished[:40]!r} is not "
                   "true or false (1 or 0)")
    if progress >= 100 and finished in ("true", "1"):
        rows.append({"participant": pid, "aou_part": "end", "aou_item": ""})
    return rows


def qualtrics_rows(text: str, path: str, m: dict, study: Study,
                   most: int) -> list[tuple[str, list[dict]]]:
    """Each respondent of a Qualtrics-style export as ``(source, rows)``."""
    try:
        lines = list(csv.reader(io.StringIO(text)))
    except csv.Error as exc:
        raise _bad(path, f"not CSV: {exc}") from None
    if not lines:
        raise _bad(path, "an empty export")
    header = lines[0]
    need = [c for q in ("part_a", "part_b", "attention") for t in m[q].values()
            for c in t.values()]
    need += [c for k, c in m["columns"].items() if k in m["explicit"] or k != "finished"]
    missing = [c for c in dict.fromkeys(need) if c not in header]
    if missing:
        raise _bad(path, f"the export has no column `{missing[0]}` (the mapping names it)")
    progress = header.index(m["columns"]["progress"])
    skip = 1  # then the question texts, and the ImportId row, when there
    if len(lines) > 1 and not _is_number(lines[1][progress] if progress < len(lines[1])
                                         else ""):
        skip = 2
        if len(lines) > 2 and any(c.lstrip().startswith('{"ImportId"') for c in lines[2]):
            skip = 3
    if len(lines) - skip > most:
        raise _bad(path, f"more than {most} respondents")
    out = []
    for n, line in enumerate(lines[skip:], skip + 1):
        if not any(cell.strip() for cell in line):
            continue
        where = f"{path}#line {n}"
        rec = dict(zip(header, line, strict=False))
        out.append((where, _respondent(rec, m, study, where)))
    return out
