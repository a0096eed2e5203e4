"""A study's report: ``results.json``, ``report.md``, ``report.html`` and a tidy CSV.

Every file is the same bytes for the same answers: numbers are rounded as printed, keys
keep the analysis's order, the figures are SVG without a date or random ids.

The two figures (``figure-part-a.svg``: the answers chosen per Part A expression, grouped
bars; ``figure-part-b.svg``: Part B's four answers per pair, stacked bars) are drawn by
matplotlib (the ``media`` extra), imported only here and only when a report is written.
Each bar is an SVG group whose id names its question and answer (``A1-confident``,
``B3-high``), so a reader can find it. Without matplotlib the report says so and has no
figures.
"""

from __future__ import annotations

import csv
import html
import io
import json
import os
import re

from ..core.files import write_atomic
from .answers import Row
from .spec import PART_B_OPTIONS

__all__ = ["FIGURES", "figures", "write_report"]

#: The figures' files, in the report folder, and what each shows.
FIGURES = {"figure-part-a.svg": "Answers chosen per Part A expression",
           "figure-part-b.svg": "Part B's answers per pair"}
#: The colours of Part B's answers (low, high, both, neither) and of Part A's options.
_B_COLOURS = ("#4c72b0", "#dd8452", "#8c8c8c", "#e5e5e5")


def _p(p: float | None) -> str:
    if p is None:
        return "-"
    return "< .001" if p < 0.001 else f"{p:.3f}".lstrip("0")


def _markdown(res: dict, drawn: bool) -> str:
    parts = res["participants"]
    out = [f"# {res['study']}: results", "",
           f"{parts['answered']} participants answered; {parts['kept']} kept.", ""]
    if parts["excluded"]:
        out += ["| participant | excluded because | detail |", "|---|---|---|"]
        out += [f"| {e['participant']} | {e['reason']} | {e['detail']} |"
                for e in parts["excluded"]] + [""]
    if drawn:
        out += [f"![{what}]({name})" for name, what in FIGURES.items()] + [""]
    else:
        out += ["(No figures: they need matplotlib, the `media` extra.)", ""]
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
        elif m := re.fullmatch(r"!\[([^]]*)\]\(([^)]*)\)", line):
            alt, src = html.escape(m.group(1)), html.escape(m.group(2))
            body.append(f'<figure><img src="{src}" alt="{alt}"><figcaption>{alt}'
                        "</figcaption></figure>")
        elif line:
            body.append(f"<p>{html.escape(line)}</p>")
    if table:
        body.append("</table>")
    return ("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>"
            f"{html.escape(title)}</title><style>table{{border-collapse:collapse}}"
            "td{border:1px solid #ccc;padding:2px 6px}img{max-width:100%}</style></head><body>\n"
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


def _bars(res: dict, part: str) -> tuple[list[str], list[str], list[list[int]]]:
    """The questions answered in ``part`` ("part_a" or "part_b"), the options and the
    counts (one row a question), as the analysis gives them."""
    entries = [e for e in res[part] if "n" in e]
    options = list(entries[0]["options"]) if entries else []
    return ([e["id"] for e in entries], options,
            [[e["options"][o]["count"] for o in options] for e in entries])


def _svg(fig) -> bytes:
    """``fig`` as SVG, the same bytes every time: ids from a fixed salt, no date, no
    software version."""
    import matplotlib

    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "aou-study", "svg.id": "aou-figure",
                                "svg.fonttype": "path"}):
        fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
    return buf.getvalue()


def figures(res: dict) -> dict[str, bytes]:
    """The report's figures (:data:`FIGURES`) as SVG bytes.

    Raises:
        ImportError: matplotlib is not installed.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    out = {}
    items, options, counts = _bars(res, "part_a")
    fig, ax = plt.subplots(figsize=(8, 4))
    width = 0.8 / max(len(options), 1)
    cmap = plt.get_cmap("tab10")
    for j, o in enumerate(options):
        bars = ax.bar([i + (j - (len(options) - 1) / 2) * width for i in range(len(items))],
                      [row[j] for row in counts], width, label=o, color=cmap(j % 10))
        for item, rect in zip(items, bars, strict=True):
            rect.set_gid(f"{item}-{o}")
    ax.set_xticks(range(len(items)), items)
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("participants")
    ax.set_title("Part A: the answer chosen for each expression")
    if options:
        ax.legend(fontsize="small", ncols=min(len(options), 6), loc="upper center",
                  bbox_to_anchor=(0.5, -0.1), frameon=False)
    fig.tight_layout()
    out["figure-part-a.svg"] = _svg(fig)
    plt.close(fig)
    items, options, counts = _bars(res, "part_b")
    fig, ax = plt.subplots(figsize=(8, 1.5 + 0.3 * len(items)))
    left = [0] * len(items)
    for j, o in enumerate(options):
        col = [row[j] for row in counts]
        bars = ax.barh(range(len(items)), col, 0.7, left=left, label=o,
                       color=_B_COLOURS[j % 4], edgecolor="#555555", linewidth=0.5)
        for item, rect in zip(items, bars, strict=True):
            rect.set_gid(f"{item}-{o}")
        left = [a + b for a, b in zip(left, col, strict=True)]
    ax.set_yticks(range(len(items)), items)
    ax.invert_yaxis()
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("participants")
    ax.set_title("Part B: which of the pair shows the state more")
    if options:
        ax.legend(fontsize="small", ncols=len(options), loc="upper center",
                  bbox_to_anchor=(0.5, -0.12 * 8 / (1.5 + 0.3 * len(items))),
                  frameon=False)
    fig.tight_layout()
    out["figure-part-b.svg"] = _svg(fig)
    plt.close(fig)
    return out


def write_report(folder: str, res: dict, rows: list[Row], reads: list[str]) -> list[str]:
    """The report's files in ``folder`` (made when missing), never over an input: the
    figures too when matplotlib is installed."""
    try:
        drawn: dict[str, bytes] = figures(res)
    except ImportError:
        drawn = {}
    md = _markdown(res, bool(drawn))
    files = {"results.json": (json.dumps(res, indent=2, ensure_ascii=False) + "\n").encode(),
             "report.md": md.encode(), "report.html": _html(md, res["study"]).encode(),
             "answers.csv": _tidy(rows).encode(), **drawn}
    out = []
    for name, data in files.items():
        path = os.path.join(folder, name)
        write_atomic(path, data, inputs=reads)
        out.append(path)
    return out
