"""What the studio does with its file and its robot's files on disk: Save, Reload, and
the builds an edit made elsewhere starts (:class:`Filing`, a part of
:class:`~.app.Studio`).

The file is the truth. Save writes the text of the motion shown, through :mod:`.disk`:
never over an edit made on disk since, nor through a link swapped in. A change on disk
is built at once; one that fails leaves the last good motion on screen, and Save
refuses to write it over the file. A change of the robot's files (its description, URDF
or a mesh) builds the motion shown again on the robot as it now is.
"""

from __future__ import annotations

from typing import Any

from ..core.diagnostics import AouError
from .engine import Motion

__all__ = ["Filing"]

#: UTF-8's byte-order mark, as some editors save it.
_BOM = "\ufeff".encode()


class Filing:
    """Save, Reload and the builds of changes on disk; the studio's state it reads
    (``shown``, ``file_text``, ``base_bytes``, ``disk``, ``engine``...) is
    :class:`~.app.Studio`'s."""

    path: str
    shown: Any
    shown_base: bytes
    file_text: str
    base_text: str
    base_bytes: bytes
    recording: bool
    disk: Any
    engine: Any
    status: Any
    _busy: Any

    def _show(self, m: Motion, drawn: bool = False) -> None:
        raise NotImplementedError

    def _say(self, m: Motion, note: str = "") -> None:
        raise NotImplementedError

    def save(self) -> str:
        """Write the text of the motion shown into the file (atomic); the path.

        Raises:
            AouError: I502 when the file is not written (said in the page too): the path
                is now a link, a folder or a special file, or the file changed on disk
                since the motion shown was read from it (Reload takes it).
        """
        with self._busy:  # a build under way finishes first: Save writes what it shows
            m, base = self.shown, self.shown_base
        if m is None or self.recording or (m.text == self.file_text and
                                           base == self.base_bytes):
            return self.path
        data = m.text.encode()
        if base.startswith(_BOM):  # the file's byte-order mark stays
            data = _BOM + data
        try:
            self.disk.save(data, expect=base)
        except AouError as err:
            self._say(Motion(self.path, "", tuple(err.diagnostics)),
                      "Nothing was saved: the file is as it was. Reload takes the text on "
                      "disk (the values set here go).")
            raise
        self.file_text = m.text
        self.base_bytes = self.shown_base = data
        self.status.content += " · saved"
        return self.path

    def _save_clicked(self) -> None:
        try:
            self.save()
        except AouError:  # said in the page
            pass

    def reload(self) -> Motion | None:
        """Take the file's text as it is on disk (unsaved values go) and build it."""
        return self._changed(force=True)

    def _changed(self, force: bool = False) -> Motion | None:
        """The file changed on disk: it is the truth, build it (unsaved values go). A
        text that fails leaves the last good motion on screen, and Save refuses to write
        it over the file."""
        try:
            data = self.disk.read()
            text = self.disk.text(data)
        except AouError as err:
            failed = Motion(self.path, "", tuple(err.diagnostics))
            self._say(failed)
            return failed
        if data == self.base_bytes and not force:
            return None  # what the studio read or saved last
        self.file_text, self.base_text, self.base_bytes = text, text, data
        with self._busy:
            m = self.engine.build(text, self.path)
        if m.ok:
            self._show(m)
        else:
            self._say(m, "The file on disk does not build; the motion shown is the last "
                      "good one (Save will not write it over the file).")
        return m

    def _robot_changed(self) -> None:
        """A file of the robot changed on disk (its description, URDF or a mesh): the
        motion shown is built again on the robot as it is now."""
        text = self.shown.text if self.shown is not None and self.shown.text else \
            self.file_text
        with self._busy:
            m = self.engine.build(text, self.path)
        if m.ok:
            self._show(m)
        else:
            self._say(m, "The robot's files changed and this motion no longer builds on "
                      "it; the motion shown is the last good one.")
