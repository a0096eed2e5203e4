"""How ``--jobs N`` splits a batch where workers are forked: this process builds the
shortest file first (so the workers are copies of a warm process), a batch with one file
left to compile after it never starts a worker, and copies of one text stay together."""

import shutil

import pytest

from aou_dsl.build import batch, pool
from aou_dsl.build.builder import build_file
from aou_dsl.build.parallel import build_many
from aou_dsl.compiler.output import encode
from aou_dsl.core.options import BuildOptions
from aou_dsl.lang.linter import lint_file

from .conftest import BEHAVIOURS, INVALID

OPTIONS = BuildOptions(rate=100.0)

pytestmark = pytest.mark.skipif(not pool.can_fork(), reason="workers are spawned here")


class _Started(Exception):
    """A pool was started."""


def _no_pool(*args, **kwargs):
    raise _Started


def _documents(results) -> list[bytes | None]:
    return [None if r.document is None else encode(r.document, "json") for r in results]


def test_two_files_and_refused_ones_never_start_a_worker(monkeypatch):
    """Two files that compile: the shortest builds here and warms this process; the
    other alone would gain nothing from a worker but its start. Files lint refuses cost
    nothing and do not count."""
    paths = [str(BEHAVIOURS / "curious.aou"), "no/such/file.aou",
             str(INVALID / "invalid_bad_character.aou"), str(BEHAVIOURS / "confident.aou")]
    monkeypatch.setattr(pool, "BuildPool", _no_pool)
    got = list(build_many(paths, OPTIONS, jobs=2))
    assert [r.path for r in got] == paths
    assert _documents(got) == _documents(build_file(p, OPTIONS) for p in paths)


def test_three_files_start_a_worker(monkeypatch):
    paths = [str(BEHAVIOURS / f"{n}.aou") for n in ("curious", "confident", "hesitant")]
    monkeypatch.setattr(pool, "BuildPool", _no_pool)
    with pytest.raises(_Started):
        list(build_many(paths, OPTIONS, jobs=2))


def test_copies_of_a_text_are_one_group_longest_motion_first(tmp_path):
    names = ("hesitant", "inactive", "hesitant", "curious", "inactive")
    paths = []
    for k, name in enumerate(names):
        shutil.copy(BEHAVIOURS / f"{name}.aou", tmp_path / f"{k}_{name}.aou")
        paths.append(str(tmp_path / f"{k}_{name}.aou"))
    lints = [lint_file(p) for p in paths] + [lint_file("no/such/file.aou")] * 2
    # hesitant (22 s of motion) before curious (13 s) before inactive (3 s); the two
    # unreadable files are groups of their own, whatever their (empty) text
    assert batch._groups(lints) == [(0, 2), (3,), (1, 4), (5,), (6,)]


def test_copies_split_across_a_worker_give_what_each_build_alone_gives(tmp_path):
    paths = []
    for k in range(3):
        for name in ("hesitant", "confident", "curious"):
            shutil.copy(BEHAVIOURS / f"{name}.aou", tmp_path / f"{k}_{name}.aou")
            paths.append(str(tmp_path / f"{k}_{name}.aou"))
    got = list(build_many(paths, OPTIONS, jobs=2))
    assert [r.path for r in got] == paths
    assert _documents(got) == _documents(build_file(p, OPTIONS) for p in paths)
