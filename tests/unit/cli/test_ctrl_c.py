"""Ctrl-C exits 130 even when a library turns the interrupt into another error on its
way up (NumPy does, when it lands while its C extension is being imported), and a plain
internal error still exits 2."""

import os
import signal
import time

import pytest

from aou_dsl.cli import commands
from aou_dsl.cli.args import EXIT_INTERRUPTED, EXIT_USAGE


@pytest.fixture
def python_sigint():
    """SIGINT handled as Python does by default, whatever the test runner set."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def _interrupted_import(args):
    try:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(5)  # the handler runs before this ends
    except KeyboardInterrupt:
        raise ImportError('PyCapsule_Import could not import module "datetime"') from None
    raise AssertionError("SIGINT was not delivered")


def _broken(args):
    raise ImportError('PyCapsule_Import could not import module "datetime"')


def test_an_interrupt_that_became_an_import_error_exits_130(monkeypatch, capsys,
                                                            python_sigint):
    monkeypatch.setitem(commands._COMMANDS, "lint", _interrupted_import)
    assert commands.main(["lint", "x.aou"]) == EXIT_INTERRUPTED
    err = capsys.readouterr().err
    assert "aouc: interrupted" in err and "internal error" not in err
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # put back


def test_the_same_error_without_ctrl_c_is_an_internal_error(monkeypatch, capsys,
                                                            python_sigint):
    monkeypatch.setitem(commands._COMMANDS, "lint", _broken)
    assert commands.main(["lint", "x.aou"]) == EXIT_USAGE
    assert "aouc: internal error: ImportError" in capsys.readouterr().err
