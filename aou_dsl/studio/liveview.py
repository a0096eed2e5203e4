"""What the live studio shows beside the arm, as small HTML and SVG pieces for the page.

- the camera's view: for the geometric model, the scene drawn as its pinhole camera sees
  it (the tag, the occluders in front of it, the light); for the rendered camera, its
  last frame;
- the confidence over the last seconds, coloured by the state the arm expressed;
- the state, intensity and confidence now, as the page's ``#aou-live`` element with
  ``data-`` attributes (what a test or a script reads).

Pure: data in, text out.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Sequence

import numpy as np

from ..live.loop import Tick
from ..live.world import HEIGHT, WIDTH, Box, Scene, face_frame, project, tag_points

__all__ = ["STATE_COLOURS", "camera_png", "camera_svg", "confidence_plot", "state_html"]

#: One colour per expressed state (those of ``aouc live --render``'s plot).
STATE_COLOURS = {"confident": "#2ea043", "curious": "#1f77b4", "hesitant": "#ff7f0e",
                 "fearful": "#d62728", "inactive": "#7f7f7f"}
_PLOT_W, _PLOT_H = 300, 110


def _hull(pts: np.ndarray) -> np.ndarray:
    """The convex hull of 2D points, counter-clockwise (Andrew's monotone chain)."""
    p = sorted(map(tuple, pts))
    if len(p) < 3:
        return np.asarray(p)

    def half(points):
        out: list[tuple[float, float]] = []
        for q in points:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (q[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (q[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(q)
        return out

    lower, upper = half(p), half(reversed(p))
    return np.asarray(lower[:-1] + upper[:-1])


def _polygon(pts: np.ndarray, fill: str, extra: str = "") -> str:
    xy = " ".join(f"{x:.1f},{y:.1f}" for x, y in pts)
    return f'<polygon points="{xy}" fill="{fill}"{extra}/>'


def _box_corners(b: Box) -> np.ndarray:
    c, h = np.asarray(b.center, float), np.asarray(b.half, float)
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    return c + signs * h


def camera_svg(scene: Scene, visible: float | None = None) -> str:
    """The geometric model's view of ``scene`` (320 x 240, as its pinhole camera): the
    tag on its face, then every occluder nearer the camera than the tag over it, all as
    bright as the light. ``visible``: the fraction of the tag the model sees (said in
    the image's ``data-visible``)."""
    grey = int(round(min(1.0, max(0.0, scene.light)) * 200))
    shade = lambda v: int(round(v * min(1.0, max(0.0, scene.light))))  # noqa: E731
    parts = [f'<svg id="aou-camera" data-visible="{-1 if visible is None else visible:.3f}" '
             f'viewBox="0 0 {WIDTH} {HEIGHT}" width="100%" '
             f'style="background:rgb({grey // 3},{grey // 3},{grey // 3})">']
    cam = np.asarray(scene.camera, float)
    tag_at, _, _, _ = face_frame(scene)
    far = float(np.linalg.norm(tag_at - cam))
    corners = project(scene, tag_points(scene))
    if np.all(np.isfinite(corners)):
        w = shade(255)
        parts.append(_polygon(corners, f"rgb({w},{w},{w})", ' data-part="tag"'))
        inner = corners.mean(axis=0) + (corners - corners.mean(axis=0)) * 0.8
        parts.append(_polygon(inner, "rgb(0,0,0)"))
    # the farthest first, so that a nearer box covers a farther one
    for b in sorted(scene.occluders, key=lambda b: -float(np.linalg.norm(
            np.asarray(b.center) - cam))):
        px = project(scene, _box_corners(b))
        if not np.all(np.isfinite(px)):
            continue  # behind the camera
        near = float(np.linalg.norm(np.asarray(b.center) - cam)) < far
        r, g, bl = shade(51), shade(77), shade(128)
        parts.append(_polygon(_hull(px), f"rgb({r},{g},{bl})",
                              f' data-part="{html.escape(b.name)}"'
                              + ("" if near else ' fill-opacity="0.35"')))
    parts.append("</svg>")
    return "".join(parts)


def camera_png(grey: np.ndarray) -> str:
    """The rendered camera's last frame (grey, 0..255) as an image in the page."""
    from ..live.camera import png_grey

    data = base64.b64encode(png_grey(np.clip(grey, 0, 255).astype(np.uint8))).decode()
    return f'<img id="aou-camera" src="data:image/png;base64,{data}" width="100%">'


def confidence_plot(ticks: Sequence[Tick], now: float, window: float = 20.0) -> str:
    """The confidence of the last ``window`` seconds up to ``now``, each stretch in the
    colour of the state the arm expressed then (SVG)."""
    t0 = now - window
    x = lambda t: _PLOT_W * (t - t0) / window  # noqa: E731
    y = lambda c: 4 + (_PLOT_H - 8) * (1.0 - c)  # noqa: E731
    parts = [f'<svg id="aou-confidence" viewBox="0 0 {_PLOT_W} {_PLOT_H + 12}" width="100%">']
    for c in (0.0, 0.5, 1.0):
        parts.append(f'<line x1="0" x2="{_PLOT_W}" y1="{y(c):.1f}" y2="{y(c):.1f}" '
                     f'stroke="#ddd"/><text x="2" y="{y(c) - 2:.1f}" font-size="8">'
                     f'{c:.1f}</text>')
    shown = [tk for tk in ticks if tk.t >= t0]
    step = max(1, len(shown) // 300)
    pts = shown[::step] + ([shown[-1]] if shown and (len(shown) - 1) % step else [])
    run: list[Tick] = []
    for tk in pts:
        if run and tk.state != run[-1].state:
            parts.append(_line(run + [tk], x, y))
            run = []
        run.append(tk)
    if len(run) > 1:
        parts.append(_line(run, x, y))
    parts.append(f'<text x="{_PLOT_W - 2}" y="{_PLOT_H + 10}" font-size="8" '
                 f'text-anchor="end">the last {window:g} s</text></svg>')
    return "".join(parts)


def _line(run: list[Tick], x, y) -> str:
    xy = " ".join(f"{x(tk.t):.1f},{y(tk.confidence):.1f}" for tk in run)
    colour = STATE_COLOURS.get(run[0].state, "#000")
    return (f'<polyline points="{xy}" fill="none" stroke="{colour}" stroke-width="1.5" '
            f'data-state="{html.escape(run[0].state)}"/>')


def state_html(tick: Tick, held: str = "") -> str:
    """The state the arm expresses now, its intensity and the confidence behind it;
    ``held``: why the last re-plan was refused (the arm kept its motion)."""
    colour = STATE_COLOURS.get(tick.state, "#000")
    note = f"<p>held: {html.escape(held)}</p>" if held else ""
    return (f'<div id="aou-live" data-state="{html.escape(tick.state)}" '
            f'data-intensity="{tick.intensity:g}" data-confidence="{tick.confidence:.3f}" '
            f'data-t="{tick.t:.2f}"><p><b style="color:{colour}">{html.escape(tick.state)}'
            f"</b> at intensity {tick.intensity:g}; confidence {tick.confidence:.2f} "
            f"(uncertainty {tick.uncertainty:.2f})</p>{note}</div>")
