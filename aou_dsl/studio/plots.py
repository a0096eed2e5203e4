"""The studio's numbers, as small HTML and SVG pieces for the page.

- the velocity profile with the episodes shaded (the data of ``aouc plot``,
  :func:`aou_dsl.media.plot.profile_data`), and the timeline of the episodes with the
  current time marked;
- the C-V map: the five states, the border of the hesitant region, the file's point;
- each descriptor the file declares beside its measured value;
- the diagnostics with their hints;
- with ``--fit``, the values fitted to the arm (declared -> fitted, what binds).

Pure: data in, text out (deterministic, so the page changes only when the motion does).
"""

from __future__ import annotations

import html
from collections.abc import Iterable

import numpy as np

from ..core.codes import C314
from ..core.diagnostics import Diagnostic
from ..lang.cv import CANONICAL, CVPoint
from ..lang.descriptors import REGISTRY, Descriptors
from .kind_controls import colour_of

__all__ = ["cv_map", "descriptor_table", "diagnostics_html", "fitted_html", "timeline",
           "velocity_profile"]

_W, _H = 300, 120
#: What a fitted value is, when it is no descriptor (``--fit``'s own words).
_FIT_KEYS = {"f": "shiver frequency", "for": "shiver duration", "a": "acceleration",
             "v": "tilt velocity"}


def _rgb(kind: str) -> str:
    r, g, b = colour_of(kind)
    return f"rgb({r},{g},{b})"


def _bands(episodes, t0: float, span: float, h: float, alpha: float) -> list[str]:
    out = []
    for kind, a, b in episodes:
        x0, x1 = _W * (a - t0) / span, _W * (b - t0) / span
        out.append(f'<rect x="{x0:.1f}" y="0" width="{max(x1 - x0, 0.5):.1f}" '
                   f'height="{h}" fill="{_rgb(kind)}" fill-opacity="{alpha}">'
                   f'<title>{kind} {a - t0:.2f}-{b - t0:.2f} s</title></rect>')
    return out


def velocity_profile(t: np.ndarray, speed: np.ndarray,
                     episodes: Iterable[tuple[str, float, float]]) -> str:
    """The end-effector speed over time, the episodes shaded (SVG)."""
    t0, span = float(t[0]), max(float(t[-1] - t[0]), 1e-6)
    top = max(float(np.max(speed)), 1e-3) * 1.15
    step = max(1, len(t) // 300)
    pts = " ".join(f"{_W * (x - t0) / span:.1f},{_H * (1 - v / top):.1f}"
                   for x, v in zip(t[::step], speed[::step], strict=True))
    parts = [f'<svg id="aou-profile" viewBox="0 0 {_W} {_H + 14}" width="100%">',
             *_bands(episodes, t0, span, _H, 0.25),
             f'<polyline points="{pts}" fill="none" stroke="black" stroke-width="1.2"/>',
             f'<text x="2" y="10" font-size="9">{top / 1.15:.3f} m/s peak</text>',
             f'<text x="2" y="{_H + 12}" font-size="9">0 s</text>',
             f'<text x="{_W - 2}" y="{_H + 12}" font-size="9" text-anchor="end">'
             f'{span:.2f} s</text></svg>']
    return "".join(parts)


def timeline(episodes: Iterable[tuple[str, float, float]], t0: float, duration: float,
             now: float) -> str:
    """The episodes as coloured bars, the current time ``now`` [s from the start] marked."""
    span = max(duration, 1e-6)
    x = _W * min(max(now, 0.0), span) / span
    parts = [f'<svg id="aou-timeline" data-now="{now:.3f}" viewBox="0 0 {_W} 26" '
             f'width="100%">', *_bands(episodes, t0, span, 16, 0.85),
             f'<line x1="{x:.1f}" x2="{x:.1f}" y1="0" y2="20" stroke="black" '
             f'stroke-width="2"/><text x="{_W - 2}" y="25" font-size="8" '
             f'text-anchor="end">{now:.2f} / {span:.2f} s</text></svg>']
    return "".join(parts)


def cv_map(point: CVPoint, label: str) -> str:
    """The C-V plane: the five states, the hesitant diamond, and the file's point."""
    s = 200

    def xy(c: float, v: float) -> tuple[float, float]:
        return s / 2 + c * s * 0.4, s / 2 - v * s * 0.4

    diamond = " ".join("{:.0f},{:.0f}".format(*xy(c, v))
                       for c, v in ((1, 0), (0, 1), (-1, 0), (0, -1)))
    parts = [f'<svg id="aou-cv" viewBox="0 0 {s} {s}" width="70%">',
             f'<polygon points="{diamond}" fill="none" stroke="#7f8c8d"/>']
    for state, (c, v) in CANONICAL.items():
        x, y = xy(c, v)
        parts.append(f'<rect x="{x - 5:.0f}" y="{y - 5:.0f}" width="10" height="10" '
                     f'fill="#bdc3c7"/><text x="{x:.0f}" y="{y + (15 if v < 0.5 else -8):.0f}"'
                     f' font-size="9" text-anchor="middle">{state.value}</text>')
    x, y = xy(point.C, point.V)
    parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="5" fill="#c0392b"/>'
                 f'<text x="{x + 7:.0f}" y="{y - 6:.0f}" font-size="9" fill="#c0392b">'
                 f'{html.escape(label)} ({point.state.value})</text></svg>')
    return "".join(parts)


def _show(v: float | int | None, unit: str) -> str:
    if v is None:
        return "-"
    return f"{v}" if isinstance(v, int) else f"{v:.3g} {unit}".strip()


def descriptor_table(declared: Descriptors | None, measured: Descriptors | None) -> str:
    """Each descriptor the file declares beside its measured value (a table)."""
    rows = []
    for name, d in REGISTRY.items():
        want = declared[name] if declared is not None else None
        got = measured[name] if measured is not None else None
        if want is None and got is None or (declared is not None and want in (None, 0)
                                             and not got):
            continue
        ok = declared is None or d.matches(want, got) or (want == 0 and not got)
        rows.append(f'<tr data-descriptor="{name}"><td>{name}</td>'
                    f'<td>{_show(want, d.unit)}</td><td data-measured="{got}">'
                    f'{_show(got, d.unit)}</td><td>{"ok" if ok else "differs"}</td></tr>')
    return ('<table id="aou-descriptors" style="font-size:11px;width:100%">'
            "<tr><th>descriptor</th><th>declared</th><th>measured</th><th></th></tr>"
            + "".join(rows) + "</table>")


def diagnostics_html(diags: Iterable[Diagnostic], note: str = "") -> str:
    """The diagnostics with their codes, places and hints; ``note`` above them."""
    items = []
    for d in diags:
        hint = f"<br><i>hint: {html.escape(d.hint)}</i>" if d.hint else ""
        colour = {"error": "#c0392b", "warning": "#b9770e"}.get(str(d.severity), "#566573")
        items.append(f'<li data-code="{d.code}" style="color:{colour}"><b>{d.code}</b> '
                     f"line {d.span.line}: {html.escape(d.message)}{hint}</li>")
    head = f"<p>{html.escape(note)}</p>" if note else ""
    body = f'<ul style="font-size:11px;padding-left:14px">{"".join(items)}</ul>' if items \
        else ""
    return f'<div id="aou-diagnostics">{head}{body}</div>'


def fitted_html(diags: Iterable[Diagnostic]) -> str:
    """The values ``--fit`` changed (its C314 warnings): each as declared -> fitted with
    the joint that binds; the file keeps the declared ones."""
    items = []
    for d in diags:
        if d.code != C314 or "fitted" not in d.fields:
            continue
        f = d.fields
        what = f.get("descriptor") or _FIT_KEYS.get(str(f.get("key")), f.get("key"))
        was = f"{f['declared']}{f['unit']}" if f.get("declared") else "the default"
        binds = f" ({html.escape(str(f['joint']))} binds)" if f.get("joint") else ""
        items.append(f'<li data-key="{html.escape(str(f["key"]))}" data-line="{d.span.line}" '
                     f'data-fitted="{html.escape(str(f["fitted"]))}">line {d.span.line}: '
                     f"{html.escape(str(what))} {html.escape(was)} &rarr; "
                     f"{html.escape(str(f['fitted']))}{html.escape(str(f['unit']))}"
                     f"{binds}</li>")
    if not items:
        return '<div id="aou-fitted"><p>Fitted to the arm: nothing (every value fits).</p></div>'
    return ('<div id="aou-fitted"><p>Fitted to the arm (the motion shown; Save keeps the '
            'values of the sliders):</p><ul style="font-size:11px;padding-left:14px">'
            + "".join(items) + "</ul></div>")
