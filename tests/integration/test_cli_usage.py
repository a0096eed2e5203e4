"""Usage errors said where they belong: with the usage of the command they were given to,
as a bad argument (I504) rather than an unreadable file, a cluster that cannot be reached
as I505 at once, and a failed command leaving nothing behind, not even a folder."""

from __future__ import annotations

import socket
import tomllib

import pytest

from aou_dsl.cli.commands import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, main
from tests.conftest import BEHAVIOURS


def _free_port() -> int:
    """A loopback port nobody listens on (bound, then released)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("address, why", [
    ("notanaddress", "expected tcp://HOST:PORT"),
    ("tcp://127.0.0.1", "expected tcp://HOST:PORT"),
    ("tcp://host.invalid:8786", ""),
    (None, ""),  # a free port: nothing listens there
])
def test_a_cluster_that_cannot_be_reached_is_I505_and_nothing_is_written(
        address, why, tmp_path, capsys):
    address = address or f"tcp://127.0.0.1:{_free_port()}"
    out = tmp_path / "new" / "folder"
    argv = ["compile", str(BEHAVIOURS / "confident.aou"), "-o", f"{out}/", "--cluster", address]
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err
    assert " I505 " in err and address in err and why in err
    assert "internal error" not in err
    assert not (tmp_path / "new").exists()  # not even the output folder


def test_a_failed_compile_leaves_no_output_folder(tmp_path, capsys):
    bad = tmp_path / "bad.aou"
    bad.write_text("pause 3m\n")
    out = tmp_path / "made" / "by" / "aouc"
    assert main(["compile", str(bad), "-o", f"{out}/"]) == EXIT_ERRORS
    assert " V102 " in capsys.readouterr().err
    assert not (tmp_path / "made").exists()


def test_unknown_options_are_said_with_the_commands_usage(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["robot", "ur5", "--bogus"])
    assert stop.value.code == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.startswith("usage: aouc robot") and "unrecognized arguments: --bogus" in err


def test_robot_without_a_name_is_a_usage_error_on_stderr(capsys):
    assert main(["robot"]) == EXIT_USAGE
    out, err = capsys.readouterr()
    assert out == "" and "usage: aouc robot" in err and "--list" in err


def test_robot_writes_its_description_to_a_file(tmp_path, capsys):
    out = tmp_path / "arms" / "ur5.toml"
    assert main(["robot", "ur5", "--format", "toml", "-o", str(out)]) == EXIT_OK
    assert capsys.readouterr().out == ""  # the description went to the file
    doc = tomllib.loads(out.read_text())
    assert doc["robot"] == "ur5" and len(doc["arm_joints"]) == 6
    # ...which describes the arm again, and is never written over
    assert main(["robot", str(out), "-o", str(out)]) == EXIT_USAGE
    assert " I502 " in capsys.readouterr().err
    assert tomllib.loads(out.read_text()) == doc


def test_a_bad_vary_is_a_bad_argument_not_an_unreadable_file(tmp_path, capsys):
    assert main(["variants", str(BEHAVIOURS / "hesitant.aou"), "--vary", "speed=1,2",
                 "-o", str(tmp_path / "v")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert " I504 " in err and "I501" not in err and "speed" in err
    assert not (tmp_path / "v").exists()


def test_a_variant_that_would_not_lint_is_said_at_the_statement_of_the_base(tmp_path, capsys):
    """Two pauses cannot frame two retreats: the low variant is refused, at the `pause`
    line of the file that exists, naming the file it would have been."""
    base = tmp_path / "scared.aou"
    base.write_text("approach a=0.12\npause 1s x4\nretreat 5cm a=1.5 x2\n"
                    "shiver 5deg f=3Hz for 1.5s\n")
    out = tmp_path / "stim"
    assert main(["variants", str(base), "--vary", "pause_count=2,6", "-o", str(out)]) \
        == EXIT_ERRORS
    err = capsys.readouterr().err
    line = next(ln for ln in err.splitlines() if "[error]" in ln)
    assert line.startswith(f"{base}:2:1:") and "low variant" in line
    assert "scared-pause_count-low.aou" in line
    assert not out.exists()


def test_an_error_pickles_whole_so_a_worker_can_send_it():
    import pickle

    from aou_dsl.core.diagnostics import AouError, Span, diag

    err = AouError([diag("R406", "a peak the joints cannot make", Span.whole_file("a.json")),
                    diag("I501", "cannot read `b`", Span.whole_file("b"))])
    back = pickle.loads(pickle.dumps(err))
    assert isinstance(back, AouError) and back.diagnostics == err.diagnostics
    assert str(back) == str(err)


def test_a_file_whose_measurement_fails_fails_alone(tmp_path, capsys, monkeypatch):
    """When measure refuses to report on one file's motion, that file fails with measure's
    diagnostic and nothing written for it; the files after it are still built."""
    import aou_dsl.measuring.measured as descriptors
    from aou_dsl.core.diagnostics import AouError, Span, diag

    real = descriptors.measure

    def refuse_long(tr, *a, **kw):
        if tr.duration > 10.0:
            raise AouError(diag("R406", "refused for the test", Span.whole_file(tr.path)))
        return real(tr, *a, **kw)

    monkeypatch.setattr(descriptors, "measure", refuse_long)
    names = ["confident", "hesitant", "fearful"]  # 4.5 s, 22 s, 12 s of motion
    out = tmp_path / "out"
    argv = ["compile", *(str(BEHAVIOURS / f"{n}.aou") for n in names), "-o", f"{out}/",
            "--jobs", "1"]
    assert main(argv) == EXIT_ERRORS
    err = capsys.readouterr().err
    assert err.count(" R406 ") == 2 and "[3/3]" in err
    assert sorted(p.name for p in out.iterdir()) == ["confident.json"]
