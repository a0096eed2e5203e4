"""The geometric model's calibration against the rendered camera: sweeps of one variable
at a time (the fit) and of others (held out), the camera's output on each, the fit, and
the model's error on the held-out sweeps.

``tools/calibrate_perception.py`` runs it and writes docs/perception-calibration.csv;
:func:`fit` reads that data back, so the model's constants (:data:`.geometric.FIT`) can be
checked against it. Needs the ``perception`` extra.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import replace
from typing import Any

import numpy as np

from .geometric import (
    FIT,
    Features,
    Ramp,
    confidence_of,
    features,
    fit_falloff,
    fit_ramp,
    image_quality,
    tag_quality,
)
from .world import Box, Scene

__all__ = ["COLUMNS", "NOISE_COLUMNS", "evaluate", "fit", "measure", "noise", "noise_sigma",
           "read_csv", "state_of", "sweeps", "write_csv"]

COLUMNS = ("set", "sweep", "x", "visible", "size_px", "blur_px", "light", "shake_px",
           "detected",
           "tag", "sharpness", "brightness", "confidence")
NOISE_COLUMNS = ("sweep", "x", "ticks", "mean", "std", "step")
BASE = Scene()


def _card(y: float, z: float = 0.06) -> Box:
    """A card standing between the camera and the target, its centre at ``(0.45, y, z)``."""
    return Box((0.45, y, z), (0.005, 0.03, 0.06), "card")


def _orbit(angle_deg: float, dist: float = 0.42) -> Scene:
    a = math.radians(angle_deg)
    tx, ty, _ = BASE.target
    return replace(BASE, camera=(tx - dist * math.cos(a), ty + dist * math.sin(a), 0.15))


def sweeps(points: int = 16) -> list[tuple[str, str, float, Scene]]:
    """``(set, sweep, x, scene)`` for every point: the fit's sweeps each move one variable
    from the clear view; the held-out ones move others (orbit, a card from above, light
    and distance together, a shaking camera)."""
    lin = np.linspace
    out: list[tuple[str, str, float, Scene]] = []
    for sweep, a, b in (("distance", 0.45, -1.3), ("speed", 0.0, 1.8), ("light", 0.0, 1.0),
                        ("card", 0.08, -0.02), ("shake", 0.0, 1.5)):
        out += [("fit", sweep, x, _scene_of(sweep, x)) for x in lin(a, b, points)]
    for a in lin(0.0, 82.0, points):
        out.append(("held", "orbit", a, _orbit(a)))
    for z in lin(0.20, 0.10, points):
        out.append(("held", "card_down", z, replace(BASE, occluders=(_card(0.01, z),))))
    for k, light in enumerate(lin(0.05, 0.9, points)):
        x = 0.3 - 1.2 * k / max(1, points - 1)
        out.append(("held", "light_distance", light,
                    replace(BASE, light=light, camera=(x, 0.0, 0.15))))
    for v in lin(0.0, 1.2, points):
        out.append(("held", "dim_speed", v, replace(BASE, light=0.75,
                                                    target_velocity=(0.0, 0.0, v))))
    return out


def measure(points: list[tuple[str, str, float, Scene]], repeats: int = 2, seed: int = 0
            ) -> list[dict[str, Any]]:
    """The camera's single-frame output at every point (``repeats`` frames, each with its
    own sensor noise, averaged), with the model's variables beside it."""
    from .camera import Camera, fuse
    from .camera import tag_quality as frame_quality

    cam = Camera(BASE, seed=seed)
    rows = []
    try:
        for which, sweep, x, scene in points:
            frames = [cam.frame(scene) for _ in range(repeats)]
            tag = float(np.mean([frame_quality(f) for f in frames]))
            sharp = float(np.mean([f.sharpness for f in frames]))
            bright = float(np.mean([f.brightness for f in frames]))
            f = features(scene)
            rows.append({"set": which, "sweep": sweep, "x": float(x), "visible": f.visible,
                         "size_px": f.size_px, "blur_px": f.blur_px, "light": f.light,
                         "shake_px": f.shake_px,
                         "detected": float(np.mean([fr.detected for fr in frames])),
                         "tag": tag, "sharpness": sharp, "brightness": bright,
                         "confidence": fuse(tag, sharp, bright)})
    finally:
        cam.close()
    return rows


def noise(points: list[tuple[str, str, float, Scene]], seconds: float = 3.0,
          bisect: int = 3, seed: int = 0) -> list[dict[str, Any]]:
    """How much the camera's confidence wanders at a still scene, as the loop reads it:
    the camera asked at its loop rate for ``seconds`` at each point of the ``fit``
    sweeps, the confidence's mean, standard deviation and largest step between two
    answers once its window is full. Where two neighbouring points of a sweep differ by
    more than 0.1 (the detector's edge: it finds the tag in some frames only, where the
    noise is largest) the edge is bisected ``bisect`` times, each midpoint measured."""
    from .camera import CAMERA_RATE, Camera
    from .geometric import WINDOW_S

    cam = Camera(BASE, seed=seed)
    ticks = int(round(seconds * CAMERA_RATE))
    skip = int(round(WINDOW_S * CAMERA_RATE))

    def still(sweep: str, x: float, scene: Scene) -> dict[str, Any]:
        cam._seen.clear()  # a fresh window for each scene
        cam._scene = lambda t: scene
        c = np.array([cam.perceive(k / CAMERA_RATE).confidence for k in range(ticks)])[skip:]
        return {"sweep": sweep, "x": float(x), "ticks": float(len(c)), "mean": float(c.mean()),
                "std": float(c.std()), "step": float(np.abs(np.diff(c)).max())}

    rows: list[dict[str, Any]] = []
    try:
        by_sweep: dict[str, list[tuple[float, Scene]]] = {}
        for which, sweep, x, scene in points:
            if which == "fit":
                by_sweep.setdefault(sweep, []).append((x, scene))
        for sweep, pts in by_sweep.items():
            got = [still(sweep, x, sc) for x, sc in pts]
            rows += got
            for (x0, _), (x1, _), a, b in zip(pts, pts[1:], got, got[1:], strict=False):
                lo, hi, ca, cb = x0, x1, a["mean"], b["mean"]
                if abs(ca - cb) <= 0.1:
                    continue
                for _ in range(bisect):  # towards where the detector flickers
                    mid = (lo + hi) / 2.0
                    r = still(sweep, mid, _scene_of(sweep, mid))
                    rows.append(r)
                    if abs(r["mean"] - ca) > abs(r["mean"] - cb):
                        hi, cb = mid, r["mean"]
                    else:
                        lo, ca = mid, r["mean"]
    finally:
        cam.close()
    return rows


def _scene_of(sweep: str, x: float) -> Scene:
    """The scene of a ``fit`` sweep at ``x`` (as :func:`sweeps` makes them)."""
    return {"distance": lambda: replace(BASE, camera=(x, 0.0, 0.15)),
            "speed": lambda: replace(BASE, target_velocity=(0.0, x, 0.0)),
            "light": lambda: replace(BASE, light=x),
            "card": lambda: replace(BASE, occluders=(_card(x),)),
            "shake": lambda: replace(BASE, camera_velocity=(0.0, 0.3 * x, x))}[sweep]()


def noise_sigma(rows: list[dict[str, Any]]) -> float:
    """The confidence noise the regulator's default hysteresis is made for: the largest
    standard deviation of the camera's confidence at a still scene over ``rows``
    (:func:`noise`), to 3 decimals."""
    return round(max(float(r["std"]) for r in rows), 3)


def write_csv(rows: list[dict[str, Any]], columns: tuple[str, ...] = COLUMNS) -> str:
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow([r[c] if isinstance(r[c], str) else f"{r[c]:.6g}" for c in columns])
    return out.getvalue()


def read_csv(text: str) -> list[dict[str, Any]]:
    """Rows of the calibration data (numbers as floats)."""
    rows = []
    for r in csv.DictReader(io.StringIO(text)):
        rows.append({k: (v if k in ("set", "sweep") else float(v)) for k, v in r.items()})
    return rows


def _sweep(rows: list[dict[str, Any]], name: str) -> list[dict[str, Any]]:
    return [r for r in rows if r["sweep"] == name]


def fit(rows: list[dict[str, Any]]) -> tuple[dict[str, Any], dict[str, float]]:
    """The model's constants fitted to the ``fit`` sweeps, and each curve's RMS error."""
    col = lambda rs, k: np.array([r[k] for r in rs])  # noqa: E731
    errors: dict[str, float] = {}
    out: dict[str, Any] = {}
    dist, speed, light, card, shake = (_sweep(rows, n) for n in ("distance", "speed", "light",
                                                                  "card", "shake"))
    out["size_px"], errors["size_px"] = fit_ramp(col(dist, "size_px"), col(dist, "tag"))
    out["light"], errors["light"] = fit_ramp(col(light, "light"), col(light, "tag"))
    out["blur_px"], errors["blur_px"] = fit_ramp(col(speed, "blur_px"), col(speed, "tag"),
                                                 falling=True)
    out["visible"], errors["visible"] = fit_ramp(col(card, "visible"), col(card, "tag"))
    clear = [r for r in light if r["light"] == max(col(light, "light"))]
    dark = [r for r in light if r["light"] == min(col(light, "light"))]
    out["clear_sharp"] = round(float(np.mean(col(clear, "sharpness"))), 1)
    out["noise_sharp"] = round(float(np.mean(col(dark, "sharpness"))), 1)
    span = out["clear_sharp"] - out["noise_sharp"]
    rel = (col(shake, "sharpness") - out["noise_sharp"]) / span
    out["sharp_shake"], errors["sharp_shake"] = fit_falloff(col(shake, "shake_px"), rel)
    lx, by = col(light, "light"), col(light, "brightness")
    out["clear_bright"] = round(float(lx @ by / (lx @ lx)), 1)
    errors["clear_bright"] = float(np.sqrt(np.mean((out["clear_bright"] * lx - by) ** 2)))
    return out, errors


def state_of(confidence: float) -> str:
    """The state the regulator's mapping gives a confidence, before hysteresis."""
    from .regulator import PATH

    return PATH[min(4, int(round(4.0 * (1.0 - confidence))))].value


def model_confidence(r: dict[str, Any], fit_: dict[str, Any] | None = None) -> float:
    """The geometric model's single-frame confidence at a row's variables."""
    f = Features(r["visible"], r["size_px"], r["blur_px"], r["light"], r["shake_px"])
    return confidence_of(tag_quality(f, fit_), image_quality(f, fit_)[2])


def evaluate(rows: list[dict[str, Any]], fit_: dict[str, Any] | None = None,
             which: str = "held") -> dict[str, float]:
    """The model's error against the camera on the rows of set ``which``: RMS and largest
    absolute error of the confidence, and the share of points in the same state."""
    rs = [r for r in rows if r["set"] == which]
    model = np.array([model_confidence(r, fit_ or FIT) for r in rs])
    cam = np.array([r["confidence"] for r in rs])
    same = np.mean([state_of(a) == state_of(b) for a, b in zip(model, cam, strict=True)])
    return {"points": float(len(rs)), "rms": float(np.sqrt(np.mean((model - cam) ** 2))),
            "max": float(np.max(np.abs(model - cam))), "same_state": float(same)}


def fit_text(out: dict[str, Any]) -> str:
    """The fit as the source of :data:`.geometric.FIT`."""
    lines = ["FIT: dict[str, Any] = {"]
    for k, v in out.items():
        if isinstance(v, Ramp):
            cut = "" if v.cut is None else f", {v.cut!r}"
            lines.append(f'    "{k}": Ramp({v.lo!r}, {v.hi!r}{cut}),')
        else:
            lines.append(f'    "{k}": {v!r},')
    return "\n".join(lines + ["}"])

