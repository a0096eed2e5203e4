"""Watching the studio's file: an edit saved in an editor reloads it.

The folder is watched, not the file: many editors save by writing a new file and
renaming it over the old one, which a watch on the old file would miss.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

__all__ = ["Watcher"]


class Watcher:
    """Calls ``on_change()`` (on its own thread) whenever ``path`` is written."""

    def __init__(self, path: str, on_change: Callable[[], None]) -> None:
        self.path = os.path.realpath(path)
        self.on_change = on_change
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="aou-studio-watch",
                                        daemon=True)
        self._thread.start()

    def _run(self) -> None:
        from watchfiles import watch

        folder = os.path.dirname(self.path)
        mine = self._is_mine
        for _ in watch(folder, watch_filter=lambda _c, p: mine(p), stop_event=self._stop,
                       debounce=100, step=20, yield_on_timeout=False, recursive=False):
            if os.path.exists(self.path):
                self.on_change()

    def _is_mine(self, p: str) -> bool:
        return os.path.realpath(p) == self.path

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2)
