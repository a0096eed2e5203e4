"""``aouc render``: stimulus videos from PyBullet's headless renderer (TinyRenderer).

Frames are drawn at ``fps`` from the trajectory interpolated at each frame time, so the
video lasts as long as the motion (real time). MP4 goes through imageio with
imageio-ffmpeg (which ships its own ffmpeg); GIF through Pillow, with frame delays that
add up to the exact duration (GIF delays are whole centiseconds). Nothing here needs a
display.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from ..files import atomic
from ..files import check_output as _check_output

__all__ = ["Camera", "frame_times", "render_video"]


@dataclass(frozen=True)
class Camera:
    """Where the virtual camera looks from. Defaults: a three-quarter view from the
    robot's side, 30 deg off the side view, so the approach and retreat read clearly and
    horizontal gazes (across the line of sight) still show depth; it looks at ``target``
    (None: halfway between the base and the goal, at the goal's height)."""

    distance: float = 1.2  # m
    yaw: float = 30.0  # deg
    pitch: float = -15.0  # deg
    target: tuple[float, float, float] | None = None
    width: int = 640
    height: int = 480
    fov: float = 50.0  # deg


def frame_times(duration: float, fps: float) -> np.ndarray:
    """Times of the frames [s]: ``k / fps`` for every whole frame of the motion."""
    return np.arange(int(math.floor(duration * fps + 1e-9)) + 1) / fps


def _frames(traj, camera: Camera, fps: float, scene_options, progress) -> list[np.ndarray]:
    from ..robots import ROBOTS
    from ..safety.scene import Scene

    t = np.asarray(traj.t, float)
    q = np.asarray(traj.q, float)[:, traj.columns(ROBOTS[traj.robot].arm_joints)]
    goal = tuple(traj.goal)
    scene = Scene(traj.robot, goal, scene_options)
    pb, c = scene.pb, scene.client
    _pedestal(scene, goal, scene_options)
    target = camera.target or (goal[0] / 2, goal[1] / 2, goal[2])
    view = pb.computeViewMatrixFromYawPitchRoll(
        cameraTargetPosition=list(target), distance=camera.distance, yaw=camera.yaw,
        pitch=camera.pitch, roll=0, upAxisIndex=2, physicsClientId=c)
    proj = pb.computeProjectionMatrixFOV(fov=camera.fov, aspect=camera.width / camera.height,
                                         nearVal=0.05, farVal=10.0, physicsClientId=c)
    times = frame_times(float(t[-1] - t[0]), fps)
    out = []
    try:
        for k, tk in enumerate(times):
            qk = np.array([np.interp(tk + t[0], t, q[:, j]) for j in range(q.shape[1])])
            scene.set_arm(qk)
            _, _, rgb, _, _ = pb.getCameraImage(camera.width, camera.height, view, proj,
                                                renderer=pb.ER_TINY_RENDERER,
                                                physicsClientId=c)
            out.append(np.reshape(np.asarray(rgb, dtype=np.uint8),
                                  (camera.height, camera.width, 4))[:, :, :3].copy())
            progress(k + 1, len(times))
    finally:
        scene.close()
    return out


def _pedestal(scene, goal, options) -> None:
    """A grey column from the table up to the target, drawn only (no collision shape), so
    that the target reads as standing on something rather than floating."""
    if options.table_height is None or options.target_size <= 0:
        return
    bottom = goal[2] - options.target_size / 2
    height = bottom - options.table_height
    if height <= 0.005:
        return
    pb, c = scene.pb, scene.client
    half = [options.target_size / 3, options.target_size / 3, height / 2]
    visual = pb.createVisualShape(pb.GEOM_BOX, halfExtents=half, rgbaColor=[0.6, 0.6, 0.6, 1],
                                  physicsClientId=c)
    pb.createMultiBody(0, -1, visual, basePosition=[goal[0], goal[1],
                                                    options.table_height + height / 2],
                       physicsClientId=c)


def _progress_bar(label: str):
    """A progress bar on stderr: redrawn in place on a terminal, every 10 % otherwise."""
    tty = sys.stderr.isatty()
    state = {"shown": -1}

    def show(done: int, total: int) -> None:
        pct = int(100 * done / total)
        if tty:
            bar = "#" * (pct // 5) + "-" * (20 - pct // 5)
            end = "\n" if done == total else ""
            print(f"\r{label} [{bar}] {pct:3d}% frame {done}/{total}", end=end,
                  file=sys.stderr, flush=True)
        elif pct // 10 != state["shown"] // 10 or done == total:
            state["shown"] = pct
            print(f"{label}: {pct}% ({done}/{total} frames)", file=sys.stderr, flush=True)

    return show


def render_video(trajs: list, path: str, *, fps: float = 30.0, camera: Camera = Camera(),
                 scene_options=None, quiet: bool = False) -> dict:
    """Render one trajectory, or several side by side, into ``path`` (.mp4 or .gif).

    Trajectories of different lengths are padded with their last frame. Written to a
    temporary file and renamed when complete.

    Returns:
        ``{"frames": N, "fps": fps, "duration": seconds, "size": [w, h]}``.
    """
    from ..safety.scene import SceneOptions

    fmt = check_output(path)
    # Import the encoder first: a missing one should fail before minutes of rendering.
    if fmt == "mp4":
        import imageio.v2 as imageio
        import imageio_ffmpeg  # noqa: F401  (imageio's ffmpeg plugin needs it)
    else:
        from PIL import Image
    opts = scene_options or SceneOptions()
    clips = []
    for i, tr in enumerate(trajs):
        label = "rendering" if len(trajs) == 1 else f"rendering {i + 1}/{len(trajs)}"
        clips.append(_frames(tr, camera, fps, opts,
                             (lambda d, t: None) if quiet else _progress_bar(label)))
    n = max(len(c) for c in clips)
    frames = [np.concatenate([c[min(k, len(c) - 1)] for c in clips], axis=1)
              for k in range(n)]
    with atomic(path) as tmp:
        if fmt == "mp4":
            with imageio.get_writer(tmp, format="FFMPEG", fps=fps, codec="libx264",
                                    quality=8, macro_block_size=8,
                                    ffmpeg_log_level="error") as w:
                for f in frames:
                    w.append_data(f)  # type: ignore[attr-defined]
        else:
            cs = [round((k + 1) * 100 / fps) - round(k * 100 / fps) for k in range(n)]
            images = [Image.fromarray(f) for f in frames]
            images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                           duration=[10 * d for d in cs], loop=0, optimize=False)
    h, w = frames[0].shape[:2]
    return {"frames": n, "fps": fps, "duration": n / fps, "size": [w, h]}


def check_output(path: str) -> str:
    """Check a video path before rendering: .mp4 or .gif, in a folder that exists."""
    return _check_output(path, ("mp4", "gif"))
