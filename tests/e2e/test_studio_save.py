"""Save never loses a file: it writes where the file was opened, never through a link,
into a folder or a special file swapped in since, never over an edit made on disk since
the studio read the file, and a slider's value lands on its own statement whatever
line-like characters come before it. What it refuses is said in the page."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")

from aou_dsl.core.diagnostics import AouError
from aou_dsl.studio.app import Studio

ROOT = str(Path(__file__).resolve().parents[2])
HESITANT = open(os.path.join(ROOT, "behaviours", "hesitant.aou"), encoding="utf-8").read()


@pytest.fixture
def studio_of(tmp_path):
    """``studio_of(text)``: a studio (not watching the file) of ``text`` in ``h.aou``."""
    made = []

    def start(text: str = HESITANT, watch: bool = False):
        path = tmp_path / "h.aou"
        path.write_bytes(text.encode())
        s = Studio(str(path), port=0, watch=watch).start()
        made.append(s)
        return s, path

    yield start
    for s in made:
        s.close()


def _moved(studio, **values) -> None:
    m = studio.set_values({**studio.sliders.values(), **values})
    assert m.ok, m.diagnostics


def test_save_through_a_link_swapped_in_writes_nothing_anywhere(studio_of, tmp_path):
    studio, path = studio_of()
    _moved(studio, retreat_acceleration=0.2)
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    os.replace(str(path), str(tmp_path / "moved.aou"))  # as an attacker swaps it
    os.symlink("victim.txt", path)
    with pytest.raises(AouError) as err:
        studio.save()
    assert "I502" in str(err.value) and "link" in str(err.value)
    assert victim.read_text() == "precious\n"
    assert os.readlink(path) == "victim.txt"
    assert (tmp_path / "moved.aou").read_text() == HESITANT
    assert 'data-code="I502"' in studio.diags.content and "Nothing was saved" in \
        studio.diags.content
    assert sorted(os.listdir(tmp_path)) == ["h.aou", "moved.aou", "victim.txt"]


@pytest.mark.parametrize("swap", ["folder", "fifo"])
def test_save_onto_a_folder_or_a_fifo_swapped_in_refuses(studio_of, tmp_path, swap):
    studio, path = studio_of()
    _moved(studio, pause_duration=2.0)
    os.unlink(path)
    if swap == "folder":
        os.mkdir(path)
        (path / "inside").write_text("kept\n")
    else:
        os.mkfifo(path)
    start = time.monotonic()
    with pytest.raises(AouError) as err:
        studio.save()
    assert time.monotonic() - start < 10  # a FIFO is not opened for reading
    assert ("a folder" if swap == "folder" else "a FIFO (a named pipe)") in str(err.value)
    if swap == "folder":
        assert (path / "inside").read_text() == "kept\n"
    else:
        assert not path.is_file() and path.exists()
    assert sorted(os.listdir(tmp_path)) == ["h.aou"]


def test_save_over_a_newer_edit_on_disk_refuses_and_reload_takes_it(studio_of, tmp_path):
    studio, path = studio_of()
    _moved(studio, retreat_acceleration=0.2)
    edited = HESITANT + "# a note, and a line that does not build yet\npause\n"
    path.write_text(edited)  # in an editor, while the studio runs (its watch is late)
    with pytest.raises(AouError) as err:
        studio.save()
    assert "changed on disk" in str(err.value) and "Reload" in str(err.value)
    assert path.read_text() == edited
    assert "I502" in studio.diags.content
    m = studio.reload()  # the page's Reload: the file's text, which does not build
    assert not m.ok and studio.base_text == edited
    with pytest.raises(AouError):  # the motion shown is the old text's: still refused
        studio.save()
    assert path.read_text() == edited
    fixed = edited.replace("pause\n", "")
    path.write_text(fixed)
    m = studio.reload()
    assert m.ok and studio.shown.text == fixed
    _moved(studio, retreat_acceleration=0.2)
    studio.save()  # now from the file as it is: the note stays
    assert path.read_text() == fixed.replace("retreat 0.06m a=0.12 x3", "retreat 0.06m a=0.2 x3")
    assert sorted(os.listdir(tmp_path)) == ["h.aou"]


def test_an_edit_on_disk_that_does_not_build_is_not_saved_over_when_watched(studio_of):
    studio, path = studio_of(watch=True)
    _moved(studio, retreat_acceleration=0.2)
    edited = HESITANT.replace("pause 1.67s x5", "pause 1.67s x5\n# next: a shiver\nshiver")
    path.write_text(edited)
    end = time.monotonic() + 60
    while studio.base_text != edited and time.monotonic() < end:  # the watch saw it
        time.sleep(0.1)
    assert studio.base_text == edited
    with pytest.raises(AouError):
        studio.save()
    assert path.read_text() == edited


@pytest.mark.parametrize("mark", ["\f", "\v", "\x1c", "\x85", "\u2028", "\u2029"])
def test_a_slider_edits_its_own_statement_after_a_line_like_character(studio_of, tmp_path,
                                                                      mark):
    text = HESITANT.replace("(Table II", f"{mark}(Table II", 1)
    studio, path = studio_of(text)
    _moved(studio, retreat_acceleration=0.2)
    studio.save()
    saved = path.read_bytes().decode()
    assert saved == text.replace("retreat 0.06m a=0.12 x3", "retreat 0.06m a=0.2 x3")
    assert "approach a=0.05\n" in saved


def test_save_keeps_the_mode_and_writes_only_the_file(studio_of, tmp_path):
    studio, path = studio_of()
    os.chmod(path, 0o640)
    _moved(studio, pause_duration=2.0)
    studio.save()
    assert "pause 2s x5" in path.read_text()
    assert oct(os.stat(path).st_mode & 0o777) == oct(0o640)
    assert sorted(os.listdir(tmp_path)) == ["h.aou"]
    studio.save()  # nothing new: nothing written, nothing refused
    assert "pause 2s x5" in path.read_text()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_the_command_prints_the_address_with_its_token_and_ctrl_c_exits_130(tmp_path):
    path = tmp_path / "h.aou"
    path.write_text(HESITANT)
    proc = subprocess.Popen(
        [sys.executable, "-m", "aou_dsl", "studio", str(path), "--port", str(_free_port())],
        stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, cwd=tmp_path)
    try:
        line = ""
        end = time.monotonic() + 240
        while time.monotonic() < end:
            line = proc.stderr.readline()
            if not line or line.startswith("aouc studio: http"):
                break
        url = line.split()[2]
        assert "/?token=" in url and len(url.split("token=")[1]) >= 32
        with urllib.request.urlopen(url, timeout=30) as r:
            assert r.status == 200
        bare = url.split("?")[0]
        with pytest.raises(urllib.error.HTTPError) as err:
            urllib.request.urlopen(bare, timeout=30)
        assert err.value.code == 403
    finally:
        proc.send_signal(signal.SIGINT)
        _, rest = proc.communicate(timeout=60)
    assert proc.returncode == 130, rest
    assert "aouc studio: stopped" in rest and "Traceback" not in rest
    assert path.read_text() == HESITANT and os.listdir(tmp_path) == ["h.aou"]
