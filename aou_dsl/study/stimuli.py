"""The stimuli of a study and the keys of their videos (:mod:`.build` draws them).

Every Part A behaviour and every Part B variant is a :class:`Stim`: its blind id, the
text compiled and the file it came from. A video is keyed by the sha256 of what it
depends on (aou's version, the text, the robot's name and file contents, the render
settings) and, once compiled, by its motion too; the cache maps keys to the videos
drawn.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass

from ..core.codes import E702
from ..core.diagnostics import AouError, Span, diag
from .spec import Study

__all__ = ["CACHE", "GENERATOR", "RENDER_DEFAULTS", "WORK", "Stim", "file_sha", "jatos_path",
           "load_cache", "manifest_path", "motion_key", "plan_stimuli", "read_text",
           "render_one", "render_settings", "robot_file", "sha256_hex", "video_key"]

GENERATOR = "aouc study build"
#: The study folder's cache of rendered videos (never served: ``serve`` refuses it).
CACHE = ".aou-cache.json"
#: Where a video is drawn before it is named by its hash.
WORK = ".aou-work"
RENDER_DEFAULTS = {"width": 640, "height": 480, "fps": 30}


@dataclass(frozen=True)
class Stim:
    """One video: its blind id, role (``A``, or ``low``/``high`` of a pair), the
    behaviour file it comes from, the text compiled, and what the manifest records."""

    item: str
    role: str
    path: str
    text: str
    state: str | None
    descriptor: str | None = None
    value: float | None = None

    @property
    def label(self) -> str:
        return self.item if self.role == "A" else f"{self.item} {self.role}"


def manifest_path(site: str) -> str:
    """The manifest of the site ``site``: beside it, never inside it."""
    return os.path.normpath(site) + ".manifest.json"


def jatos_path(site: str) -> str:
    return os.path.normpath(site) + ".jzip"


def sha256_hex(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def plan_stimuli(study: Study) -> list[Stim]:
    """Every video the study shows: Part A's behaviours, then each pair's two variants
    (made as ``aouc variants`` makes them)."""
    from ..lang.linter import lint_file
    from ..media.variants import base_stem, make_variants

    out = [Stim(s.id, "A", s.path, read_text(s.path), s.state) for s in study.part_a]
    for p in study.pairs:
        r = lint_file(p.path)
        if r.behaviour is None or r.source is None:
            raise AouError(diag(E702, f"pair {p.id}: `{p.path}` does not lint",
                                Span.whole_file(study.path)))
        prefix = os.path.join(os.path.dirname(p.path), f"{base_stem(p.path)}-{p.descriptor}")
        try:
            variants = make_variants(r.behaviour, r.source, p.descriptor, p.low, p.high, prefix)
        except AouError as exc:
            first = exc.diagnostics[0]
            raise AouError(diag(E702, f"pair {p.id} ({os.path.basename(p.path)}, "
                                f"{p.descriptor}): {first.code} {first.message}",
                                Span.whole_file(study.path))) from None
        for v in variants:
            out.append(Stim(p.id, v.label, p.path, v.text, p.state, p.descriptor, v.value))
    return out


def read_text(path: str) -> str:
    from ..core.inputs import read_input_text

    return read_input_text(path, "behaviour")


def robot_file(study: Study) -> tuple[str, str]:
    """(the robot as the compiler takes it, the file that describes it)."""
    from ..core.robot_specs import ROBOTS

    if study.robot in ROBOTS:
        import example_robot_data as erd

        sub = ROBOTS[study.robot].urdf
        return study.robot, os.path.join(erd.getModelPath(sub), sub)
    path = os.path.join(os.path.dirname(os.path.abspath(study.path)), study.robot)
    return path, path


def render_settings(study: Study) -> dict:
    return {k: study.render.get(k, v) for k, v in RENDER_DEFAULTS.items()}


def video_key(stim: Stim, robot: str, robot_sha: str, render: dict) -> str:
    """The sha256 of everything a stimulus's video depends on."""
    from ..version import __version__

    doc = {"aou": __version__, "text": stim.text, "robot": os.path.basename(robot),
           "robot_sha256": robot_sha, "render": render}
    return sha256_hex(json.dumps(doc, sort_keys=True).encode())


def motion_key(stim: Stim, robot: str, robot_sha: str, render: dict) -> str:
    """The sha256 of the motion a stimulus's text compiles to (its samples, joints and
    goal) with the robot and render settings: two texts that differ only where the motion
    does not (a comment, a variant's value equal to its base's) share a video."""
    import numpy as np

    from ..core.options import BuildOptions
    from ..driver.builder import build_source
    from ..version import __version__

    res = build_source(stim.text, stim.path, BuildOptions(robot=robot, check=False))
    if not res.ok:
        first = next(d for d in res.diagnostics if d.severity == "error")
        raise AouError(diag(E702, f"{stim.label} ({os.path.basename(stim.path)}"
                            f"{f', {stim.descriptor}={stim.value:g}' if stim.descriptor else ''}"
                            f") does not compile: {first.code} {first.message}",
                            Span.whole_file(stim.path)))
    tr = res.trajectory
    h = hashlib.sha256(json.dumps({"aou": __version__, "robot": os.path.basename(robot),
                                   "robot_sha256": robot_sha, "render": render,
                                   "joints": list(tr.joint_names), "goal": tr.goal},
                                  sort_keys=True).encode())
    h.update(np.ascontiguousarray(tr.t, dtype="<f8").tobytes())
    h.update(np.ascontiguousarray(tr.q, dtype="<f8").tobytes())
    return h.hexdigest()


def render_one(text: str, label: str, robot: str, out: str, render: dict) -> list[str]:
    """Compile ``text`` and draw its video into ``out`` (in a process of its own); the
    error messages, none when it worked."""
    from ..core.options import BuildOptions
    from ..driver.builder import build_source
    from ..media.render import Camera, render_video

    try:
        res = build_source(text, label, BuildOptions(robot=robot, check=False))
        if not res.ok:
            return [f"{d.code} {d.message}" for d in res.diagnostics if d.severity == "error"]
        render_video([res.trajectory], out, fps=float(render["fps"]), quiet=True, jobs=1,
                     camera=Camera(width=int(render["width"]), height=int(render["height"])))
    except AouError as exc:
        return [f"{d.code} {d.message}" for d in exc.diagnostics]
    return []


def file_sha(path: str) -> str | None:
    try:
        with open(path, "rb") as fh:
            return sha256_hex(fh.read())
    except OSError:
        return None


def load_cache(site: str, part: str = "videos") -> dict[str, str]:
    """The cache's key -> video hash entries of ``part`` (``videos``: by text,
    ``motions``: by motion); an unreadable cache is an empty one."""
    try:
        with open(os.path.join(site, CACHE), "rb") as fh:
            doc = json.loads(fh.read(10_000_000))
    except (OSError, ValueError):
        return {}
    videos = doc.get(part) if isinstance(doc, dict) else None
    if not isinstance(videos, dict):
        return {}
    return {k: v for k, v in videos.items() if isinstance(k, str) and isinstance(v, str)
            and len(v) == 64 and all(c in "0123456789abcdef" for c in v)}
