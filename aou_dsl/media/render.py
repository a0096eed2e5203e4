"""``aouc render``: stimulus videos from PyBullet's headless renderer (TinyRenderer).

Frames are drawn at ``fps`` from the trajectory interpolated at each frame time, so the
video lasts as long as the motion (real time). A frame whose configuration is exactly
the previous one's (the arm holds still) reuses its image; the others are drawn by
several processes at once (one per core by default). MP4 goes through imageio with
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

__all__ = ["Camera", "frame_configurations", "frame_times", "render_configurations",
           "render_video"]


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


def frame_configurations(traj, fps: float) -> np.ndarray:
    """The arm's joint positions at every frame time, interpolated, shape (F, n)."""
    from ..arms.load import load_robot

    t = np.asarray(traj.t, float)
    q = np.asarray(traj.q, float)[:, traj.columns(load_robot(traj.robot).spec.arm_joints)]
    times = frame_times(float(t[-1] - t[0]), fps) + t[0]
    return np.column_stack([np.interp(times, t, q[:, j]) for j in range(q.shape[1])])


_SCENES: dict = {}


def _scene(robot: str, goal: tuple, options):
    """A drawn scene (visual meshes, the pedestal under the target) per robot, goal and
    options, kept for the next video: loading the meshes takes a second."""
    from ..safety.scene import Scene

    key = (robot, goal, options)
    if key not in _SCENES:
        if len(_SCENES) >= 4:
            for old in _SCENES.values():
                old.close()
            _SCENES.clear()
        scene = Scene(robot, goal, options)
        _pedestal(scene, goal, options)
        _SCENES[key] = scene
    return _SCENES[key]


def render_configurations(robot: str, goal: tuple, options, camera: Camera,
                          qs: np.ndarray) -> np.ndarray:
    """RGB images (k, h, w, 3) of the arm at each row of ``qs`` (k, n)."""
    scene = _scene(robot, goal, options)
    pb, c = scene.pb, scene.client
    target = camera.target or (goal[0] / 2, goal[1] / 2, goal[2])
    view = pb.computeViewMatrixFromYawPitchRoll(
        cameraTargetPosition=list(target), distance=camera.distance, yaw=camera.yaw,
        pitch=camera.pitch, roll=0, upAxisIndex=2, physicsClientId=c)
    proj = pb.computeProjectionMatrixFOV(fov=camera.fov, aspect=camera.width / camera.height,
                                         nearVal=0.05, farVal=10.0, physicsClientId=c)
    out = np.empty((len(qs), camera.height, camera.width, 3), dtype=np.uint8)
    for k, qk in enumerate(qs):
        scene.set_arm(qk)
        _, _, rgb, _, _ = pb.getCameraImage(camera.width, camera.height, view, proj,
                                            renderer=pb.ER_TINY_RENDERER,
                                            physicsClientId=c)
        out[k] = np.reshape(np.asarray(rgb, dtype=np.uint8),
                            (camera.height, camera.width, 4))[:, :, :3]
    return out


#: Frames per task handed to a drawing process.
_CHUNK = 24


@dataclass
class _Clip:
    """One trajectory's frames: the configurations to draw (each run of identical
    frames once) and, per frame, which drawn image it shows."""

    robot: str
    goal: tuple
    qs: np.ndarray  # (D, n) configurations drawn
    owner: np.ndarray  # (F,) frame -> index into qs

    @classmethod
    def of(cls, traj, fps: float) -> _Clip:
        qk = frame_configurations(traj, fps)
        new = np.ones(len(qk), dtype=bool)
        new[1:] = np.any(qk[1:] != qk[:-1], axis=1)
        if traj.goal is None:  # a recording without a goal: the target where the hand ends
            from ..measuring.recording import final_goal

            goal = final_goal(traj)
        else:
            goal = traj.goal
        return cls(traj.robot, tuple(float(x) for x in goal), qk[new], np.cumsum(new) - 1)


class _Drawer:
    """Draws the clips' configurations in chunks of :data:`_CHUNK`, in ``jobs`` processes
    (or here), and hands back the image of any (clip, drawn index) in frame order:
    chunks are submitted in the order the video needs them and dropped once passed."""

    def __init__(self, clips: list[_Clip], camera: Camera, options, jobs: int, progress):
        self.clips, self.camera, self.options, self.progress = clips, camera, options, progress
        self.total = sum(len(c.qs) for c in clips)
        self.done = 0
        self.ready: dict[tuple[int, int], object] = {}
        self.pool = None
        if jobs > 1 and self.total >= 2 * _CHUNK:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            chunks = sorted(((int(np.argmax(c.owner == k * _CHUNK)), i, k)
                             for i, c in enumerate(clips)
                             for k in range(-(-len(c.qs) // _CHUNK))))
            self.pool = ProcessPoolExecutor(max_workers=min(jobs, len(chunks)),
                                            mp_context=multiprocessing.get_context("spawn"))
            for _, i, k in chunks:
                self.ready[(i, k)] = self.pool.submit(
                    render_configurations, clips[i].robot, clips[i].goal, options, camera,
                    clips[i].qs[k * _CHUNK:(k + 1) * _CHUNK])

    def image(self, clip: int, index: int) -> np.ndarray:
        key = (clip, index // _CHUNK)
        got = self.ready.get(key)
        if got is None or not isinstance(got, np.ndarray):
            c = self.clips[clip]
            got = got.result() if got is not None else render_configurations(  # type: ignore[attr-defined]
                c.robot, c.goal, self.options, self.camera,
                c.qs[key[1] * _CHUNK:(key[1] + 1) * _CHUNK])
            for old in [k for k in self.ready if k[0] == clip and k[1] < key[1]]:
                del self.ready[old]  # frames only move forward
            self.ready[key] = got
            self.done += len(got)
            self.progress(self.done, self.total)
        return got[index % _CHUNK]  # type: ignore[index]

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)


def _video_frames(clips: list[_Clip], drawer: _Drawer):
    """The video's frames in order, the clips side by side (a shorter clip holds its
    last frame)."""
    n = max(len(c.owner) for c in clips)
    for k in range(n):
        parts = [drawer.image(i, int(c.owner[min(k, len(c.owner) - 1)]))
                 for i, c in enumerate(clips)]
        yield parts[0] if len(parts) == 1 else np.concatenate(parts, axis=1)


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
                 scene_options=None, quiet: bool = False, jobs: int | None = None) -> dict:
    """Render one trajectory, or several side by side, into ``path`` (.mp4 or .gif).

    Trajectories of different lengths are padded with their last frame. Written to a
    temporary file and renamed when complete. Frames are drawn in ``jobs`` processes
    (None: one per core).

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
    clips = [_Clip.of(tr, fps) for tr in trajs]
    label = "rendering" if len(trajs) == 1 else f"rendering {len(trajs)} side by side"
    drawer = _Drawer(clips, camera, opts, jobs or _cores(),
                     (lambda d, t: None) if quiet else _progress_bar(label))
    n = max(len(c.owner) for c in clips)
    try:
        with atomic(path) as tmp:
            if fmt == "mp4":  # frames go to the encoder as they are drawn
                with imageio.get_writer(tmp, format="FFMPEG", fps=fps, codec="libx264",
                                        quality=8, macro_block_size=8,
                                        ffmpeg_log_level="error") as w:
                    for f in _video_frames(clips, drawer):
                        w.append_data(f)  # type: ignore[attr-defined]
                        size = f.shape
            else:
                cs = [round((k + 1) * 100 / fps) - round(k * 100 / fps) for k in range(n)]
                images = [Image.fromarray(f) for f in _video_frames(clips, drawer)]
                size = (images[0].height, images[0].width)
                images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                               duration=[10 * d for d in cs], loop=0, optimize=False)
    finally:
        drawer.close()
    return {"frames": n, "fps": fps, "duration": n / fps, "size": [size[1], size[0]]}


def _cores() -> int:
    from ..parallel import default_jobs

    return default_jobs()


def check_output(path: str) -> str:
    """Check a video path before rendering: .mp4 or .gif, in a folder that exists."""
    return _check_output(path, ("mp4", "gif"))
