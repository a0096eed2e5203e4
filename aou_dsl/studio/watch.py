"""Watching the studio's file and its robot's files: an edit saved in an editor reloads.

The ``.aou`` file is watched, and so is every file its motion is made from: the robot
description it names (or ``--robot``), that description's URDF and the URDF's meshes
(:func:`~aou_dsl.robot.files_read.files_read`). A lowered limit in the robot file
builds the motion again, and the page shows the refusal.

Folders are watched, not files: many editors save by writing a new file and renaming it
over the old one, which a watch on the old file would miss. The set of files is found
again after every change (an edited ``robot`` line or ``urdf`` names other files).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable, Sequence

__all__ = ["Watcher"]


class Watcher:
    """Calls ``on_change()`` (on its own thread) whenever ``path`` is written, and
    ``on_robot_change()`` (``on_change`` when not given) whenever a file of its robot
    is: the robot ``robot`` (None: the one the file names) with ``package_dirs``."""

    def __init__(self, path: str, on_change: Callable[[], None], *,
                 robot: str | None = None, package_dirs: Sequence[str] = (),
                 on_robot_change: Callable[[], None] | None = None) -> None:
        self.path = os.path.realpath(path)
        self.on_change = on_change
        self.on_robot_change = on_robot_change or on_change
        self.robot = robot
        self.package_dirs = tuple(package_dirs)
        self.robot_files = self._robot_files()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="aou-studio-watch",
                                        daemon=True)
        self._thread.start()

    def _robot_files(self) -> frozenset[str]:
        """The files the motion is made from, the ``.aou`` itself aside (real paths)."""
        from ..robot.files_read import files_read

        try:
            found = files_read([self.path], self.robot, self.package_dirs)
        except Exception:  # noqa: BLE001 - a file it cannot follow: the build says why
            found = []
        return frozenset(os.path.realpath(f) for f in found) - {self.path}

    def _folders(self) -> list[str]:
        return sorted({os.path.dirname(p) for p in (self.path, *self.robot_files)
                       if os.path.isdir(os.path.dirname(p))})

    def _run(self) -> None:
        from watchfiles import watch

        while not self._stop.is_set():
            folders = self._folders()
            for changes in watch(*folders, watch_filter=lambda _c, p: self._is_watched(p),
                                 stop_event=self._stop, debounce=100, step=20,
                                 yield_on_timeout=False, recursive=False):
                changed = {os.path.realpath(p) for _, p in changes}
                robot = bool(changed & self.robot_files)
                self.robot_files = self._robot_files()
                if self.path in changed and os.path.exists(self.path):
                    self.on_change()
                if robot:
                    self.on_robot_change()
                if self._folders() != folders:  # other files now: watch their folders
                    break

    def _is_watched(self, p: str) -> bool:
        real = os.path.realpath(p)
        return real == self.path or real in self.robot_files

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2)
