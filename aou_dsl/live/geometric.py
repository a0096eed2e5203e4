"""A geometric model of what the camera would see: sub-millisecond and deterministic, for
tests and the live loop.

From a :class:`~.world.Scene` it works out four things a detector depends on:

- ``visible``: the fraction of the tag the camera sees: rays from the camera to the tag's
  four corners and to the centres of a 6 x 6 grid over it (its data cells), each tested
  against every box occluder (slab tests), the field of view and the face's side;
- ``size_px``: the tag's size in the image (a pinhole camera: side x focal length /
  distance, foreshortened by the viewing angle);
- ``blur_px``: how far the tag moves in the image during the exposure (speed across the
  line of sight x exposure x focal length / distance);
- ``light``: the scene's brightness;
- ``shake_px``: how far the whole image moves during the exposure (the camera's own
  motion), which blurs everything and so lowers the image's sharpness.

They map to a confidence with the same fusion as the rendered camera (:mod:`.camera`),
each factor a ramp fitted to the camera's output over a sweep of that variable alone
(``tools/calibrate_perception.py`` writes the data, docs/perception-calibration.csv, and
the fit below; docs/live.md gives its error):

    tag   = ramp(visible) * ramp(size_px) * ramp(blur_px) * ramp(light), averaged over the
            last WINDOW_S seconds (the camera's window of frames)
    image = min(1, sharpness / SHARP_REF) * min(1, brightness / BRIGHT_REF)
            sharpness = NOISE_SHARP + (CLEAR_SHARP - NOISE_SHARP) * light^2 / (1 + shake_px / K)
            brightness = CLEAR_BRIGHT * light
    confidence = TAG_WEIGHT * tag + (1 - TAG_WEIGHT) * image
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .perception import Estimate, Evidence
from .world import Scene, blur_px, shake_px, tag_points, tag_size_px, visible_fraction

__all__ = ["FIT", "WINDOW_S", "Features", "Geometric", "Ramp", "confidence_of", "features",
           "fit_ramp"]

#: The sliding window the tag's detection is averaged over [s] (the camera's too).
WINDOW_S = 1.0
#: Constants of the rendered camera's fusion (:mod:`.camera`); kept here so the model
#: needs neither PyBullet nor the detector.
SHARP_REF, BRIGHT_REF, TAG_WEIGHT = 200.0, 100.0, 0.5


@dataclass(frozen=True)
class Ramp:
    """``clip((x - lo) / (hi - lo), 0, 1)`` (falling when ``hi < lo``), and 0 past
    ``cut`` on the side of ``lo`` (where the detector stops finding the tag at all)."""

    lo: float
    hi: float
    cut: float | None = None

    def __call__(self, x: float) -> float:
        if self.cut is not None and (x < self.cut if self.hi > self.lo else x > self.cut):
            return 0.0
        return min(1.0, max(0.0, (x - self.lo) / (self.hi - self.lo)))

    def many(self, x: np.ndarray) -> np.ndarray:
        y = np.clip((x - self.lo) / (self.hi - self.lo), 0.0, 1.0)
        if self.cut is not None:
            y[(x < self.cut) if self.hi > self.lo else (x > self.cut)] = 0.0
        return y


#: The fit (tools/calibrate_perception.py prints it from docs/perception-calibration.csv).
FIT: dict[str, Any] = {
    "size_px": Ramp(7.127, 19.44, 9.488),
    "light": Ramp(0.02564, 0.8974, 0.1333),
    "blur_px": Ramp(10.19, 2.548, 6.626),
    "visible": Ramp(0.0, 0.02564, 1.0),
    "clear_sharp": 859.4,
    "noise_sharp": 15.4,
    "sharp_shake": 2.216,
    "clear_bright": 170.1,
}


@dataclass(frozen=True)
class Features:
    """What the model reads off a scene (the module's docstring)."""

    visible: float
    size_px: float
    blur_px: float
    light: float
    shake_px: float = 0.0


def features(scene: Scene) -> Features:
    """The four variables of ``scene``."""
    return Features(visible_fraction(scene, tag_points(scene, cells=8)), tag_size_px(scene),
                    blur_px(scene), float(scene.light), shake_px(scene))


def tag_quality(f: Features, fit: dict[str, Any] | None = None) -> float:
    """The expected quality of one frame's detection (the camera's margin x size)."""
    fit = fit or FIT
    return (fit["visible"](f.visible) * fit["size_px"](f.size_px) * fit["blur_px"](f.blur_px)
            * fit["light"](f.light))


def image_quality(f: Features, fit: dict[str, Any] | None = None) -> tuple[float, float, float]:
    """The expected sharpness and brightness of the image, and its quality."""
    fit = fit or FIT
    sharp = fit["noise_sharp"] + (fit["clear_sharp"] - fit["noise_sharp"]) * (
        max(0.0, f.light) ** 2 * 1.0 / (1.0 + f.shake_px / fit["sharp_shake"]))
    bright = fit["clear_bright"] * max(0.0, f.light)
    return sharp, bright, min(1.0, sharp / SHARP_REF) * min(1.0, bright / BRIGHT_REF)


def confidence_of(tag: float, image: float) -> float:
    """The fused confidence from the window's tag quality and the image's quality."""
    return min(1.0, max(0.0, TAG_WEIGHT * tag + (1.0 - TAG_WEIGHT) * image))


class Geometric:
    """The geometric model as a :class:`~.perception.Perception` of a scene that changes
    with time (``scene(t) -> Scene``, or one scene)."""

    def __init__(self, scene: Callable[[float], Scene] | Scene, *, window: float = WINDOW_S,
                 fit: dict[str, Any] | None = None):
        self._scene = scene if callable(scene) else (lambda t: scene)
        self.window_s, self.fit = window, fit or FIT
        self._seen: deque[tuple[float, float]] = deque()

    def perceive(self, t: float) -> Estimate:
        scene = self._scene(t)
        f = features(scene)
        q = tag_quality(f, self.fit)
        self._seen.append((t, q))
        while self._seen and self._seen[0][0] <= t - self.window_s:
            self._seen.popleft()
        tag = sum(x for _, x in self._seen) / len(self._seen)
        sharp, bright, image = image_quality(f, self.fit)
        ev = Evidence("geometric", (("visible", f.visible), ("size_px", f.size_px),
                                    ("blur_px", f.blur_px), ("light", f.light),
                                    ("tag", tag), ("sharpness", sharp),
                                    ("brightness", bright)))
        seen = f.visible > 0.5 and q > 0.0
        return Estimate(confidence_of(tag, image), scene.target if seen else None, ev)


def fit_ramp(x: np.ndarray, y: np.ndarray, *, falling: bool = False, steps: int = 40
             ) -> tuple[Ramp, float]:
    """The :class:`Ramp` nearest (least squares) to the points ``(x, y)``: its ends and
    its cut on a grid of ``steps`` over the range of ``x`` (the cut one of the points'
    own ``x``, or none); and its root mean square error."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    grid = np.linspace(float(x.min()), float(x.max()), steps)
    cuts: list[float | None] = [None, *sorted(set(x.tolist()))]
    best: tuple[float, Ramp] | None = None
    for a in grid:
        for b in grid:
            if (b <= a) != falling or a == b:
                continue
            base = np.clip((x - a) / (b - a), 0.0, 1.0)
            for cut in cuts:
                pred = base.copy()
                if cut is not None:
                    pred[(x > cut) if falling else (x < cut)] = 0.0
                err = float(np.mean((pred - y) ** 2))
                if best is None or err < best[0] - 1e-12:
                    best = (err, Ramp(_g(a), _g(b), None if cut is None else _g(cut)))
    assert best is not None
    return best[1], float(np.sqrt(best[0]))


def fit_falloff(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """The ``k`` of ``1 / (1 + x / k)`` nearest (least squares) to the points, on a
    logarithmic grid; and its root mean square error."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    ks = np.geomspace(0.05, 50.0, 400)
    errs = [float(np.mean((1.0 / (1.0 + x / k) - y) ** 2)) for k in ks]
    i = int(np.argmin(errs))
    return _g(ks[i]), float(np.sqrt(errs[i]))


def _g(x: float) -> float:
    """``x`` to 4 significant digits (the fit is printed and kept as source)."""
    return float(f"{float(x):.4g}")
