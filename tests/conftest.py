"""Shared fixtures: paths to the shipped behaviours and the test fixture folders."""

import signal
import threading
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BEHAVIOURS = ROOT / "behaviours"
INVALID = Path(__file__).resolve().parent / "invalid"
VALID = Path(__file__).resolve().parent / "valid"


def pytest_configure(config: pytest.Config) -> None:
    """Ctrl-C reaches the commands the tests start as it does in a terminal. A test run
    started in the background by a shell without job control inherits SIGINT ignored,
    and every command started from it would too (exec keeps an ignored signal ignored),
    so the tests that press Ctrl-C on one would see nothing happen."""
    if threading.current_thread() is threading.main_thread() and \
            signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture
def behaviours_dir() -> Path:
    return BEHAVIOURS


def fails_with(code: str, fn, *args, **kw):
    """The one diagnostic of the AouError ``fn(*args, **kw)`` raises, checked to be
    ``code``."""
    from aou_dsl.core.diagnostics import AouError

    with pytest.raises(AouError) as err:
        fn(*args, **kw)
    (d,) = err.value.diagnostics
    assert d.code == code, d.message
    return d


# --- Running on several workers (pytest-xdist, `--dist loadgroup` in pyproject.toml) ---------

#: Modules whose tests share a cached build at module level (not a fixture, so not seen
#: by the rule below): they run on one worker, which builds it once.
SHARED_MODULE_CACHE = frozenset({"test_ros_export.py"})


def _module_scoped_fixtures(item: pytest.Item) -> list[str]:
    """The fixtures of ``item`` set up once per module (a compiled behaviour, a loaded
    robot, a browser, a language server...)."""
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return []
    return [name for name, defs in info.name2fixturedefs.items()
            if defs and defs[-1].scope == "module"]


def _group_of(item: pytest.Item) -> str | None:
    """The xdist group of a test that shares set-up with others of its module: split
    over two workers, that set-up would run once on each."""
    module = item.path.name
    if module in SHARED_MODULE_CACHE or _module_scoped_fixtures(item):
        return module
    return None


def _xdist_groups(item: pytest.Item) -> str | None:
    """The name pytest-xdist gives the groups of ``item`` (its ``xdist_group`` marks)."""
    names = {str(mark.args[0] if mark.args else mark.kwargs.get("name", "default"))
             for mark in item.iter_markers("xdist_group")}
    return "_".join(sorted(names)) or None


def _show_group_to_xdist(item: pytest.Item) -> None:
    """Put ``item``'s group where the scheduler of pytest-xdist reads it: after an ``@``
    at the end of the test's id. pytest-xdist (3.8) writes it to ``item._nodeid``, which
    pytest 9.2 no longer reads (its ids are structured, in ``item._id``): there every
    group was silently ignored, each module's shared set-up ran on both workers and a
    module-scoped fixture was set up twice. Where pytest-xdist's own suffix took (on
    an older pytest, or on marks it saw), nothing is done."""
    group = _xdist_groups(item)
    if group is None or "@" in item.nodeid:
        return
    try:
        from _pytest.nodeid import NodeId
    except ImportError:  # a pytest whose ids are plain strings, as pytest-xdist expects
        item._nodeid = f"{item.nodeid}@{group}"
    else:
        item._id = NodeId.parse(f"{item.nodeid}@{group}")


@pytest.hookimpl(trylast=True)  # after pytest-xdist's own hook, which names the groups
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Keep the tests that share a module's set-up on one worker, and on the workers
    hand the slow tests out first, so that no long test starts last while the others
    have finished (loadgroup hands out the largest groups first, then the single tests
    in this order). One process keeps the files' order: the modules' set-up runs once."""
    for item in items:
        if item.get_closest_marker("xdist_group") is None and (group := _group_of(item)):
            item.add_marker(pytest.mark.xdist_group(group))
    if hasattr(config, "workerinput"):  # a worker of pytest-xdist
        items.sort(key=lambda item: item.get_closest_marker("slow") is None)
        if config.getvalue("loadgroup"):
            for item in items:
                _show_group_to_xdist(item)
