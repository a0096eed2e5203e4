"""Every output flag obeys the output rule of ``-o`` before any work, and its refusal
names the flag given: ``--tracked`` onto the recording it tracks, ``--tracked`` without
``--track``, ``-o`` onto the ``.aou`` file it compiles."""

from __future__ import annotations

import pytest

from aou_dsl.cli.commands import main
from tests.conftest import BEHAVIOURS


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A compiled behaviour as a CSV recording (with its goal), as a logged arm gives it."""
    path = tmp_path_factory.mktemp("flags") / "n2.csv"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "--no-check",
                 "-o", str(path)]) == 0
    return path


def test_tracked_onto_the_recording_is_refused_before_the_replay(recording, capsys):
    """No report is printed: the refusal comes first, and its hint names --tracked."""
    capsys.readouterr()
    before = recording.read_bytes()
    assert main(["check", str(recording), "--robot", "panda", "--no-dynamic", "--track",
                 "--tracked", str(recording)]) == 2
    out, err = capsys.readouterr()
    assert out == ""  # no replay, no report
    assert " I502 " in err and "which this command reads" in err
    assert "choose another output with --tracked" in err and "with -o" not in err
    assert recording.read_bytes() == before


def test_tracked_without_track_is_refused_not_ignored(recording, tmp_path, capsys):
    capsys.readouterr()
    dest = tmp_path / "t.csv"
    assert main(["check", str(recording), "--robot", "panda", "--no-dynamic",
                 "--tracked", str(dest)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and " I504 " in err and "needs --track" in err
    assert not dest.exists()
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "--no-check", "--no-output",
                 "--tracked", str(dest)]) == 2
    assert " I504 " in capsys.readouterr().err and not dest.exists()


def test_tracked_onto_the_compiled_output_is_refused_before_compiling(tmp_path, capsys):
    out = tmp_path / "h.json"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "--no-check", "--track",
                 "-o", str(out), "--tracked", str(out)]) == 2
    err = capsys.readouterr().err
    assert " I502 " in err and "give --tracked a path of its own" in err
    assert not out.exists()


def test_compile_onto_its_own_aou_file_says_it_reads_it(tmp_path, capsys):
    """`-o x.aou` is refused as the input, not as an unknown format, and left whole."""
    src = tmp_path / "hesitant.aou"
    src.write_text((BEHAVIOURS / "hesitant.aou").read_text())
    before = src.read_bytes()
    assert main(["compile", str(src), "-o", str(src)]) == 2
    err = capsys.readouterr().err
    assert " I502 " in err and "which this command reads" in err
    assert "unknown output format" not in err
    assert src.read_bytes() == before
