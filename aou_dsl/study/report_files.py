"""A study's report: ``results.json``, ``report.md``, ``report.html`` and a tidy CSV.

Every file is the same bytes for the same answers: numbers are rounded as printed, keys
keep the analysis's order, the figures are SVG without a date or random ids.
"""

from __future__ import annotations

import csv
import html
import io
import json
import os

from ..core.files import write_atomic
from .answers import Row
from .spec import PART_B_OPTIONS

__all__ = ["write_report"]


def _p(p: float | None) -> str:
    if p is None:
        return "-"
    return "< .001" if p < 0.001 else f"{p:.3f}".lstrip("0")


def _markdown(res: dict) -> str:
    parts = res["participants"]
    out = [f"# {res['study']}: results", "",
           f"{parts['answered']} participants answered; {parts['kept']} kept.", ""]
    if parts["excluded"]:
        out += ["| participant | excluded because | detail |", "|---|---|---|"]
        out += [f"| {e['participant']} | {e['reason']} | {e['detail']} |"
                for e in parts["excluded"]] + [""]
    out += ["## Part A: which state each expression shows", "",
            f"Chi-squared goodness of fit against even answers; Pearson residuals "
            f"(O - E) / sqrt(E) beyond {res['threshold']} mark an answer chosen more than "
            "chance; p adjusted by Holm across every test of this report.", ""]
    for e in res["part_a"]:
        if "n" not in e:
            out += [f"### {e['id']}: no answers", ""]
            continue
        out += [f"### {e['id']} (declared {e['declared'] or 'none'}): "
                f"{e['dominant'] or 'no dominant state'}", "",
                f"chi2({e['df']}) = {e['chi2']:.2f}, p {_p(e['p'])}, Holm p "
                f"{_p(e['p_holm'])}, Cohen's w = {e['cohen_w']:.2f}, n = {e['n']}"
                + (f"; exact multinomial p {_p(e['exact_p'])} ({e['exact_method']})"
                   if e["exact_p"] is not None else ""), "",
                "| answer | count | share (95 % CI) | residual | adjusted |",
                "|---|---:|---|---:|---:|"]
        for o, v in e["options"].items():
            lo, hi = v["ci95"]
            out.append(f"| {o} | {v['count']} | {v['share']:.2f} ({lo:.2f}-{hi:.2f}) | "
                       f"{v['residual']:.2f} | {v['adjusted_residual']:.2f} |")
        if e["intensity"]:
            k = e["intensity"]
            out += ["", f"Intensity: mean {k['mean']:.2f}, median {k['median']:g}, "
                    f"SD {k['sd']:.2f} (n = {k['n']})."]
        if e["words"]:
            out += ["", "Top words: " + ", ".join(f"{w} ({c})" for w, c in e["words"]) + "."]
        out.append("")
    if res["independence"]:
        i = res["independence"]
        out += ["Expression and state chosen: chi2(" f"{i['df']}) = {i['chi2']:.2f}, p "
                f"{_p(i['p'])}, Cramer's V = {i['cramer_v']:.2f}.", ""]
    if res["confusion"]:
        opts = list(next(iter(res["confusion"].values())))
        out += ["Declared state (rows) against the state people chose:", "",
                "| declared | " + " | ".join(opts) + " |", "|---" * (len(opts) + 1) + "|"]
        out += [f"| {d} | " + " | ".join(str(row[o]) for o in opts) + " |"
                for d, row in res["confusion"].items()] + [""]
    out += ["## Part B: which of the pair shows the state more", ""]
    out += ["| pair | state | descriptor | low | high | "
            + " | ".join(PART_B_OPTIONS) + " | chi2 | p (Holm) | verdict |",
            "|---" * 12 + "|"]
    for e in res["part_b"]:
        if "n" not in e:
            continue
        counts = " | ".join(f"{e['options'][o]['count']} ({e['options'][o]['residual']:+.2f})"
                            for o in PART_B_OPTIONS)
        out.append(f"| {e['id']} | {e['state']} | {e['descriptor']} | {e['low']:g} | "
                   f"{e['high']:g} | {counts} | {e['chi2']:.2f} | {_p(e['p_holm'])} | "
                   f"{e['verdict']} |")
    out += ["", "## Participants needed", "",
            "For a goodness-of-fit test at alpha .05 with power .8:", ""]
    out += [f"- effect {w}: Part A {v['part_a']}, Part B {v['part_b']}"
            for w, v in res["power"].items()]
    return "\n".join(out) + "\n"


def _html(markdown: str, title: str) -> str:
    """The report as a page: the Markdown's tables and paragraphs, escaped."""
    body, table = [], False
    for line in markdown.splitlines():
        if line.startswith("|"):
            cells = [html.escape(c.strip()) for c in line.strip("|").split("|")]
            if set("".join(cells)) <= set("-: "):
                continue
            if not table:
                body.append("<table>")
                table = True
            body.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
            continue
        if table:
            body.append("</table>")
            table = False
        if line.startswith("#"):
            level = len(line) - len(line.lstrip("#"))
            body.append(f"<h{level}>{html.escape(line.lstrip('# '))}</h{level}>")
        elif line:
            body.append(f"<p>{html.escape(line)}</p>")
    if table:
        body.append("</table>")
    return ("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
            f"{html.escape(title)}</title><style>table{{border-collapse:collapse}}"
            "td{border:1px solid #ccc;padding:2px 6px}</style></head><body>\n"
            + "\n".join(body) + "\n</body></html>\n")


def _tidy(rows: list[Row]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["participant", "part", "item", "state", "intensity", "answer", "left",
                "order", "description", "other_text"])
    for r in rows:
        if r.part in ("A", "B"):
            w.writerow([r.participant, r.part, r.item, r.state or "", r.intensity or "",
                        r.answer or "", r.left or "", r.order or "", r.description,
                        r.other_text])
    return buf.getvalue()


def write_report(folder: str, res: dict, rows: list[Row], reads: list[str]) -> list[str]:
    """The report's files in ``folder`` (made when missing), never over an input."""
    md = _markdown(res)
    files = {"results.json": json.dumps(res, indent=2, ensure_ascii=False) + "\n",
             "report.md": md, "report.html": _html(md, res["study"]),
             "answers.csv": _tidy(rows)}
    out = []
    for name, text in files.items():
        path = os.path.join(folder, name)
        write_atomic(path, text.encode(), inputs=reads)
        out.append(path)
    return out
