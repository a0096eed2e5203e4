"""What a video shows besides the motion: captions drawn into its frames (each behaviour
of a side-by-side video is named at the top of its half, so a viewer knows which is
which), and the progress of the drawing on stderr."""

from __future__ import annotations

import sys

import numpy as np

from ..core.memo import cached

__all__ = ["caption", "progress_bar", "side_by_side"]


@cached(maxsize=16)
def _font(height: int):
    from PIL import ImageFont

    size = max(10, height // 24)
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow without FreeType's default font: the bitmap one
        return ImageFont.load_default()


def caption(frame: np.ndarray, text: str) -> np.ndarray:
    """``frame`` (H, W, 3) with ``text`` on a white band at its top, centred and cut to
    the width; the frame keeps its size."""
    from PIL import Image, ImageDraw

    if not text:
        return frame
    img = Image.fromarray(np.ascontiguousarray(frame))
    draw = ImageDraw.Draw(img)
    font = _font(img.height)
    while len(text) > 4 and draw.textlength(text, font=font) > img.width - 8:
        text = text[:-4] + "..."
    box = draw.textbbox((0, 0), text, font=font)
    band = box[3] - box[1] + 8
    draw.rectangle((0, 0, img.width, band), fill=(255, 255, 255))
    draw.text(((img.width - (box[2] - box[0])) / 2 - box[0], 4 - box[1]), text,
              fill=(20, 20, 20), font=font)
    return np.asarray(img)


def side_by_side(parts: list[np.ndarray], titles: list[str]) -> np.ndarray:
    """The frames next to each other, each captioned with its title."""
    return np.concatenate([caption(p, t) for p, t in zip(parts, titles, strict=True)], axis=1)


def progress_bar(label: str):
    """A progress bar of the images drawn on stderr: in place on a terminal, else by 10 %."""
    tty = sys.stderr.isatty()
    state = {"shown": -1}

    def show(done: int, total: int) -> None:
        pct = int(100 * done / total)
        if tty:
            bar = "#" * (pct // 5) + "-" * (20 - pct // 5)
            end = "\n" if done == total else ""
            print(f"\r{label} [{bar}] {pct:3d}% image {done}/{total}", end=end,
                  file=sys.stderr, flush=True)
        elif pct // 10 != state["shown"] // 10 or done == total:
            state["shown"] = pct
            print(f"{label}: {pct}% ({done}/{total} images)", file=sys.stderr, flush=True)

    return show
