"""A study's answers: the rows a participant's browser records, read from any store.

Each answer is a row, as jsPsych records a trial, with aou's fields:

| field | meaning |
|---|---|
| `participant` | the participant's id (a recruiting platform's, or one the page drew) |
| `aou_part` | `A` (recognition), `B` (pairs), `attention`, or `end` (the study finished) |
| `aou_item` | the question's blind id: `A1`..., `B1`... |
| `state` | Part A: the option chosen (a state, `others` or `none`) |
| `other_text`, `description` | Part A: the texts the participant wrote |
| `intensity` | Part A: the point chosen on the intensity scale, from 1 |
| `answer` | Part B: `low`, `high`, `both` or `neither`, recoded from the side shown |
| `left` | Part B: which variant was on the left (`low` or `high`) |
| `passed` | an attention check: whether it was answered right |
| `order` | the position at which the question was shown |

Read from a JSON array of rows (jsPsych's `data.get().json()`), a CSV with these
columns (jsPsych's `.csv()`), the SQLite store `aouc study serve` keeps (one row per
submission, its rows as JSON), a JATOS results archive or, through a mapping file, a
Qualtrics-style CSV export (:mod:`.imports`). Every file is untrusted: bounded, parsed
as data, every value checked against the study (E703 naming the file and the row).
"""

from __future__ import annotations

import csv
import io
import json
import os
import sqlite3
from collections.abc import Iterable
from dataclasses import dataclass

from ..core.codes import E703
from ..core.diagnostics import AouError, Span, diag
from ..core.inputs import check_regular, read_input
from .imports import is_zip, jatos_data, qualtrics_rows, read_mapping
from .spec import PART_B_OPTIONS, Study

__all__ = ["Row", "read_answers"]

#: The most rows read from one results file.
MAX_ROWS = 2_000_000
FIELDS = ("participant", "aou_part", "aou_item", "state", "other_text", "description",
          "intensity", "answer", "left", "passed", "order")


@dataclass(frozen=True)
class Row:
    """One answer, checked against the study."""

    participant: str
    part: str
    item: str
    state: str | None = None
    other_text: str = ""
    description: str = ""
    intensity: int | None = None
    answer: str | None = None
    left: str | None = None
    passed: bool | None = None
    order: int | None = None
    source: str = ""


def _bad(source: str, message: str) -> AouError:
    file = source.split("#")[0].split("!/")[0]  # a row of a file, or of an archive's member
    return AouError(diag(E703, f"{source}: {message}", Span.whole_file(file)))


def _text(v, source: str, name: str, most: int = 5000) -> str:
    if v is None:
        return ""
    if not isinstance(v, str | int) or isinstance(v, bool):
        raise _bad(source, f"`{name}` is not a text")
    return str(v)[:most]


def _int(v, source: str, name: str) -> int | None:
    if v in (None, ""):
        return None
    try:
        n = int(v)
    except (TypeError, ValueError):
        raise _bad(source, f"`{name}` is not a whole number: {str(v)[:40]!r}") from None
    if isinstance(v, float) and v != n or abs(n) > 10**9:
        raise _bad(source, f"`{name}` is not a whole number: {str(v)[:40]!r}")
    return n


def _row(raw, study: Study, source: str) -> Row | None:
    """A checked row, or None for a row of jsPsych's own (no ``aou_part``)."""
    if not isinstance(raw, dict):
        raise _bad(source, "a row is not an object")
    part = raw.get("aou_part")
    if part in (None, ""):
        return None
    if part not in ("A", "B", "attention", "end"):
        raise _bad(source, f"`aou_part` is {str(part)[:20]!r}, not A, B, attention or end")
    pid = _text(raw.get("participant"), source, "participant", 200)
    if not pid:
        raise _bad(source, "a row without a participant")
    item = _text(raw.get("aou_item"), source, "aou_item", 20)
    row = Row(pid, part, item, order=_int(raw.get("order"), source, "order"), source=source)
    if part == "A":
        if item not in {s.id for s in study.part_a}:
            raise _bad(source, f"Part A has no question `{item}`")
        state = raw.get("state")
        if state not in study.options:
            raise _bad(source, f"`{str(state)[:30]}` is not an option of Part A "
                       f"({', '.join(study.options)})")
        k = _int(raw.get("intensity"), source, "intensity")
        if k is not None and not 1 <= k <= study.intensity:
            raise _bad(source, f"intensity {k} is outside 1..{study.intensity}")
        return Row(pid, part, item, state=state,
                   other_text=_text(raw.get("other_text"), source, "other_text"),
                   description=_text(raw.get("description"), source, "description"),
                   intensity=k, order=row.order, source=source)
    if part == "B":
        if item not in {p.id for p in study.pairs}:
            raise _bad(source, f"Part B has no pair `{item}`")
        answer, left = raw.get("answer"), raw.get("left")
        if answer not in PART_B_OPTIONS or left not in (None, "", "low", "high"):
            raise _bad(source, f"pair {item}: answer `{str(answer)[:20]}` is not one of "
                       f"{', '.join(PART_B_OPTIONS)}")
        return Row(pid, part, item, answer=answer, left=left or None, order=row.order,
                   source=source)
    if part == "attention":
        passed = raw.get("passed")
        if isinstance(passed, str):
            passed = {"true": True, "false": False}.get(passed.lower())
        if not isinstance(passed, bool):
            raise _bad(source, "an attention check without `passed` true or false")
        return Row(pid, part, item, passed=passed, source=source)
    return row


def _rows_of(data, study: Study, source: str) -> Iterable[Row]:
    if not isinstance(data, list):
        raise _bad(source, "expected a JSON array of rows (jsPsych's data)")
    if len(data) > MAX_ROWS:
        raise _bad(source, f"more than {MAX_ROWS} rows")
    for i, raw in enumerate(data):
        row = _row(raw, study, f"{source}#{i + 1}")
        if row is not None:
            yield row


def _sqlite(path: str, study: Study) -> list[Row]:
    check_regular(path)
    rows: list[Row] = []
    try:
        db = sqlite3.connect(f"file:{os.path.abspath(path)}?mode=ro", uri=True)
        try:
            got = db.execute("select participant, data from submissions order by seq").fetchall()
        finally:
            db.close()
    except sqlite3.Error as exc:
        raise _bad(path, f"not a study store ({exc})") from None
    for pid, text in got:
        try:
            data = json.loads(text)
        except (TypeError, ValueError):
            raise _bad(path, f"participant {str(pid)[:40]}: the data is not JSON") from None
        rows.extend(_rows_of(data, study, f"{path}#{pid}"))
    return rows


def read_answers(paths: Iterable[str], study: Study, mapping: str | None = None) -> list[Row]:
    """Every answer of ``paths`` (JSON, CSV, the SQLite store or a JATOS archive), in
    file order; with ``mapping``, a CSV is a Qualtrics-style export read through it."""
    rows: list[Row] = []
    m = read_mapping(mapping, study) if mapping else None
    for path in paths:
        raw = read_input(path, "results")
        if raw.startswith(b"SQLite format 3\0"):
            rows.extend(_sqlite(path, study))
            continue
        if is_zip(raw):
            for source, data in jatos_data(raw, path):
                rows.extend(_rows_of(data, study, source))
            continue
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            raise _bad(path, "not UTF-8 text, a SQLite store or a zip archive") from None
        if text.lstrip().startswith("["):
            try:
                data = json.loads(text)
            except ValueError as exc:
                raise _bad(path, f"not JSON: {exc}") from None
            rows.extend(_rows_of(data, study, path))
        elif m is not None:
            for source, got in qualtrics_rows(text, path, m, study, MAX_ROWS):
                rows.extend(_rows_of(got, study, source))
        else:
            try:
                reader = csv.DictReader(io.StringIO(text))
                if not reader.fieldnames or "aou_part" not in reader.fieldnames:
                    raise _bad(path, "not JSON, and not a CSV with an `aou_part` column "
                               "(a Qualtrics-style export needs --map)")
                got = list(reader)
            except csv.Error as exc:
                raise _bad(path, f"not CSV: {exc}") from None
            rows.extend(_rows_of(got, study, path))
    return rows
