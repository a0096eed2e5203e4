"""``aouc live SCENARIO.toml``: the perception loop run headless on a scenario
(:mod:`aou_dsl.live.loop`), its recording, and a video of what the camera saw beside the
arm."""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter

from .args import EXIT_OK, EXIT_USAGE

__all__ = ["cmd_live"]

#: Video frames per second.
VIDEO_FPS = 10.0
_COLOURS = {"confident": (46, 160, 67), "curious": (31, 119, 180), "hesitant": (255, 127, 14),
            "fearful": (214, 39, 40), "inactive": (127, 127, 127)}


def cmd_live(args: argparse.Namespace) -> int:
    """Run the scenario; write the recording (``-o``) and the video (``--render``)."""
    from ..core.files import check_output, write_atomic
    from ..live import scenario as scenarios
    from ..live.camera import CAMERA_RATE
    from ..live.loop import HYSTERESIS, document, run
    from ..live.regulator import Regulator

    reads = [args.path]
    if args.output:
        check_output(args.output, ("json",), reads=reads, force=args.force)
    if args.render:
        check_output(args.render, ("mp4", "gif"), reads=reads, force=args.force)
    sc = scenarios.load(args.path)
    missing = _missing(args.perception == "camera" or bool(args.render), bool(args.render))
    if missing:
        print(f"aouc: this needs the {missing[0]} extra ({missing[1]} is missing): "
              f"pip install '.[{missing[0]}]' in aou's folder (the one with pyproject.toml)",
              file=sys.stderr)
        return EXIT_USAGE
    # every plan made before the loop starts, as a robot would: a re-plan is then warm
    clock = time.perf_counter()
    reg = Regulator(args.robot or "panda", sc.goal, hysteresis=HYSTERESIS)
    made = reg.prepare()
    if not args.quiet:
        print(f"{made} plans made for {reg.robot} in {time.perf_counter() - clock:.1f} s",
              file=sys.stderr)
    perception = _perception(args.perception, sc)
    try:
        r = run(perception, duration=sc.duration, rate=sc.rate, regulator=reg,
                title=sc.title or args.path, follow=sc.offset,
                perception_rate=CAMERA_RATE if args.perception == "camera" else None)
    finally:
        close = getattr(perception, "close", None)
        if close is not None:
            close()
    doc = document(r)
    if args.output:
        write_atomic(args.output, (json.dumps(doc, separators=(",", ":")) + "\n").encode(),
                     inputs=reads)
        print(f"wrote {args.output}", file=sys.stderr)
    if args.render:
        video(r, sc, args.render, reads, quiet=args.quiet)
        print(f"wrote {args.render}", file=sys.stderr)
    if not args.quiet:
        print(summary(r))
    return EXIT_OK


def _missing(camera: bool, media: bool) -> tuple[str, str] | None:
    """The extra and the module missing for what was asked, before any long work."""
    import importlib.util

    wanted = ([("perception", "pupil_apriltags"), ("perception", "pybullet")] if camera
              else []) + ([("media", "imageio"), ("media", "PIL")] if media else [])
    for extra, module in wanted:  # fixed names, never from the input
        if importlib.util.find_spec(module) is None:
            return extra, module
    return None


def _perception(kind: str, sc):
    if kind == "geometric":
        from ..live.geometric import Geometric

        return Geometric(sc.scene_at)
    from ..live.camera import Camera

    return Camera(sc.scene_at)


def summary(r) -> str:
    """What the run did, in a few lines: the switches, what was held and why, and how
    long the arm spent in each state."""
    lines = [f"{r.title}: {len(r.ticks)} ticks at {r.rate:g} Hz on {r.robot}"]
    for s in r.switches:
        what = f"{s.state} at intensity {s.intensity:g}"
        if s.kind == "held":
            lines.append(f"  {s.t:7.2f} s  held (not {what}): {s.reason}")
        else:
            lines.append(f"  {s.t:7.2f} s  {s.kind:8} {what}  ({1000 * s.seconds:.0f} ms)")
    share = Counter(tk.state for tk in r.ticks)
    lines.append("  time in each state: " + ", ".join(
        f"{k} {100 * v / len(r.ticks):.0f} %" for k, v in share.most_common()))
    return "\n".join(lines)


def video(r, sc, path: str, reads: list[str], *, quiet: bool = False) -> None:
    """The camera's view, the confidence over time and the arm, side by side, at
    :data:`VIDEO_FPS` (needs the media extra, and the perception extra for the view)."""
    import imageio.v2 as imageio
    import numpy as np

    from ..core.files import atomic
    from ..core.options import SceneOptions
    from ..live.camera import Camera
    from ..media.annotate import caption, progress_bar
    from ..media.render import Camera as View
    from ..media.render import frame_configurations, render_configurations

    tr = r.trajectory
    times = np.arange(0.0, min(sc.duration, tr.t[-1]), 1.0 / VIDEO_FPS)
    qs = frame_configurations(tr, VIDEO_FPS)[:len(times)]
    goal = tuple(tr.goal) if tr.goal is not None else (0.5, 0.0, 0.3)
    arm = render_configurations(tr.robot, goal, SceneOptions(), View(width=320, height=240),
                                qs)
    cam = Camera(sc.scene_at)
    ticks_t = np.array([tk.t for tk in r.ticks])
    show = (lambda d, n: None) if quiet else progress_bar("rendering the camera")
    try:
        with atomic(path, inputs=reads) as tmp:
            fmt = "FFMPEG" if path.endswith(".mp4") else "GIF"
            kw = ({"fps": VIDEO_FPS, "codec": "libx264", "quality": 8, "macro_block_size": 8,
                   "ffmpeg_log_level": "error"} if fmt == "FFMPEG"
                  else {"duration": 1.0 / VIDEO_FPS})
            with imageio.get_writer(tmp, format=fmt, **kw) as w:
                for k, t in enumerate(times):
                    grey = cam.render(sc.scene_at(float(t))).astype(np.uint8)
                    i = min(int(np.searchsorted(ticks_t, t, side="right")) - 1,
                            len(r.ticks) - 1)
                    tk = r.ticks[max(i, 0)]
                    view = caption(np.repeat(grey[:, :, None], 3, axis=2),
                                   f"camera  t={t:.1f} s")
                    plot = _plot(r.ticks[:max(i, 0) + 1], sc.duration, tk)
                    body = caption(arm[k], f"{tk.state} at intensity {tk.intensity:g}")
                    w.append_data(  # type: ignore[attr-defined]
                        np.concatenate([view, plot, body], axis=1))
                    show(k + 1, len(times))
    finally:
        cam.close()


def _plot(ticks, duration: float, now):
    """A 320 x 240 panel: the confidence over time, coloured by the state expressed."""
    import numpy as np
    from PIL import Image, ImageDraw

    from ..media.annotate import caption

    w, h, pad = 320, 240, 24
    img = Image.new("RGB", (w, h), (255, 255, 255))
    d = ImageDraw.Draw(img)
    x = lambda t: pad + (w - 2 * pad) * t / duration  # noqa: E731
    y = lambda c: h - pad - (h - 2 * pad - 16) * c  # noqa: E731
    for c in (0.0, 0.5, 1.0):
        d.line([(pad, y(c)), (w - pad, y(c))], fill=(220, 220, 220))
        d.text((2, y(c) - 6), f"{c:.1f}", fill=(90, 90, 90))
    step = max(1, len(ticks) // 400)
    pts = ticks[::step]
    for a, b in zip(pts, pts[1:], strict=False):
        d.line([(x(a.t), y(a.confidence)), (x(b.t), y(b.confidence))],
               fill=_COLOURS.get(b.state, (0, 0, 0)), width=2)
    return caption(np.asarray(img), f"confidence {now.confidence:.2f}")
