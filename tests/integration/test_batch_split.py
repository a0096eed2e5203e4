"""How ``--jobs N`` splits a batch where workers are forked: a batch of three files or
more forks its workers before this process builds anything, a batch of two never starts
a worker, and copies of one text stay together."""

import multiprocessing
import shutil
import subprocess
import sys

import pytest

from aou_dsl.compiler.output import encode
from aou_dsl.core.options import BuildOptions
from aou_dsl.driver import batch, pool
from aou_dsl.driver.builder import build_file
from aou_dsl.driver.parallel import build_many
from aou_dsl.lang.linter import lint_file
from tests.conftest import BEHAVIOURS, INVALID, ROOT

OPTIONS = BuildOptions(rate=100.0)

forking = pytest.mark.skipif(
    not sys.platform.startswith("linux") or "fork" not in multiprocessing.get_all_start_methods(),
    reason="workers are spawned here")


class _Started(Exception):
    """A pool was started."""


def _no_pool(*args, **kwargs):
    raise _Started


def _ran_alone(name: str) -> bool:
    """Whether the test ``name`` was run in a fresh pytest, and passed there: it must be
    where this process runs another thread (a pytest-xdist worker's), because a pool
    here would not fork."""
    if pool.can_fork():
        return False
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p",
                           "no:cacheprovider", f"{__file__}::{name}"], capture_output=True,
                          text=True, cwd=ROOT, check=False)
    assert proc.returncode == 0 and "1 passed" in proc.stdout, proc.stdout[-3000:]
    return True


def _documents(results) -> list[bytes | None]:
    return [None if r.document is None else encode(r.document, "json") for r in results]


@forking
def test_two_files_and_refused_ones_never_start_a_worker(monkeypatch):
    """Two files that compile: the shortest builds here and warms this process; the
    other alone would gain nothing from a worker but its start. Files lint refuses cost
    nothing and do not count."""
    paths = [str(BEHAVIOURS / "curious.aou"), "no/such/file.aou",
             str(INVALID / "invalid_bad_character.aou"), str(BEHAVIOURS / "confident.aou")]
    if _ran_alone("test_two_files_and_refused_ones_never_start_a_worker"):
        return
    monkeypatch.setattr(pool, "BuildPool", _no_pool)
    got = list(build_many(paths, OPTIONS, jobs=2))
    assert [r.path for r in got] == paths
    assert _documents(got) == _documents(build_file(p, OPTIONS) for p in paths)


@forking
def test_three_files_start_a_worker(monkeypatch):
    if _ran_alone("test_three_files_start_a_worker"):
        return
    paths = [str(BEHAVIOURS / f"{n}.aou") for n in ("curious", "confident", "hesitant")]
    monkeypatch.setattr(pool, "BuildPool", _no_pool)
    with pytest.raises(_Started):
        list(build_many(paths, OPTIONS, jobs=2))


@forking
def test_workers_start_before_this_process_builds_anything(monkeypatch):
    """No build waits for another: the workers are forked (with the libraries and the
    arm loaded) before this process builds anything, not after its first build."""
    if _ran_alone("test_workers_start_before_this_process_builds_anything"):
        return
    paths = [str(BEHAVIOURS / f"{n}.aou") for n in ("curious", "confident", "hesitant")]
    built: list[str] = []
    real = batch._build_here

    def build_here(lint, *args):
        built.append(lint.path)
        return real(lint, *args)

    def started(*args, **kwargs):
        raise _Started(list(built))

    monkeypatch.setattr(batch, "_build_here", build_here)
    monkeypatch.setattr(pool, "BuildPool", started)
    with pytest.raises(_Started) as got:
        list(build_many(paths, OPTIONS, jobs=2))
    assert got.value.args == ([],)


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


@forking
def test_copies_split_across_a_worker_give_what_each_build_alone_gives(tmp_path):
    if _ran_alone("test_copies_split_across_a_worker_give_what_each_build_alone_gives"):
        return
    paths = []
    for k in range(3):
        for name in ("hesitant", "confident", "curious"):
            shutil.copy(BEHAVIOURS / f"{name}.aou", tmp_path / f"{k}_{name}.aou")
            paths.append(str(tmp_path / f"{k}_{name}.aou"))
    got = list(build_many(paths, OPTIONS, jobs=2))
    assert [r.path for r in got] == paths
    assert _documents(got) == _documents(build_file(p, OPTIONS) for p in paths)


@forking
def test_a_batch_is_written_without_making_the_documents_lists(tmp_path, monkeypatch):
    """``aouc compile --jobs 2`` writes each file from the bytes its builder encoded
    from the trajectory's arrays: the document's lists of samples (a float object per
    sample, made in this process for every file it went through) are never made, here
    or in a worker (a copy of this process, the refusal included), and the files are
    those ``--jobs 1`` writes."""
    from aou_dsl.cli.commands import main
    from aou_dsl.compiler import output

    if _ran_alone("test_a_batch_is_written_without_making_the_documents_lists"):
        return
    paths = [str(BEHAVIOURS / f"{n}.aou") for n in ("curious", "confident", "hesitant")]
    for jobs in (1, 2):
        assert main(["compile", *paths, "-o", f"{tmp_path / str(jobs)}/", "--jobs", str(jobs),
                     "--rate", "100"]) == 0
    one = {p.name: p.read_bytes() for p in (tmp_path / "1").iterdir()}
    two = {p.name: p.read_bytes() for p in (tmp_path / "2").iterdir()}
    assert sorted(one) == ["confident.json", "curious.json", "hesitant.json"] and one == two

    def refused(*args, **kwargs):
        raise AssertionError("the document's lists were made")

    monkeypatch.setattr(output, "with_samples", refused)
    out = tmp_path / "2again"
    assert main(["compile", *paths, "-o", f"{out}/", "--jobs", "2", "--rate", "100"]) == 0
    assert {p.name: p.read_bytes() for p in out.iterdir()} == one


# --- each document written where it was built, named here in input order ---------------

_FOUR = ("curious", "confident", "hesitant", "inactive")


@forking
def test_documents_are_written_where_they_were_built_and_named_here(tmp_path, monkeypatch):
    """Into a folder that exists, ``--jobs 2`` writes no document in this process: each
    is written beside its output by the process that built it (the worker's never comes
    back through the pipe), and only named here; the files are those ``--jobs 1``
    writes, and no temporary file is left."""
    from aou_dsl.cli import dmp_cmd
    from aou_dsl.cli.commands import main

    if _ran_alone("test_documents_are_written_where_they_were_built_and_named_here"):
        return
    paths = [str(BEHAVIOURS / f"{n}.aou") for n in _FOUR]
    assert main(["compile", *paths, "-o", f"{tmp_path / 'one'}/", "--rate", "100"]) == 0
    one = {p.name: p.read_bytes() for p in (tmp_path / "one").iterdir()}

    def written_here(*args, **kwargs):
        raise AssertionError("a document was written by the command")

    monkeypatch.setattr(dmp_cmd, "write_compiled", written_here)
    (tmp_path / "two").mkdir()
    assert main(["compile", *paths, "-o", f"{tmp_path / 'two'}/", "--jobs", "2",
                 "--rate", "100"]) == 0
    assert {p.name: p.read_bytes() for p in (tmp_path / "two").iterdir()} == one
    assert sorted(one) == sorted(f"{n}.json" for n in _FOUR)


@forking
def test_a_batch_closed_early_leaves_no_file_it_staged(tmp_path):
    """A batch left after its first result (as Ctrl-C leaves it) removes the documents
    written for outputs that were never named, here and in the worker it stopped."""
    from aou_dsl.driver.delivery import Outputs

    if _ran_alone("test_a_batch_closed_early_leaves_no_file_it_staged"):
        return
    paths = [str(BEHAVIOURS / f"{n}.aou") for n in _FOUR]
    dests = tuple(str(tmp_path / f"{n}.json") for n in _FOUR)
    got = build_many(paths, OPTIONS, jobs=2, encode="json",
                     outputs=Outputs(dests, "json", paths))
    first = next(got)
    assert first.staged is not None and first.staged.startswith(str(tmp_path))
    got.close()
    assert sorted(tmp_path.iterdir()) == []


def test_an_output_that_became_an_input_is_refused_when_named(tmp_path):
    """The output rule is asked again when a staged document is named: an output that
    has become a link to an input since the command began is refused (I502), the input
    keeps its bytes, and the staged file is removed."""
    from aou_dsl.core.diagnostics import AouError
    from aou_dsl.driver.delivery import Outputs, name, stage

    source = tmp_path / "hesitant.aou"
    shutil.copy(BEHAVIOURS / "hesitant.aou", source)
    before = source.read_bytes()
    dest = tmp_path / "out" / "hesitant.json"
    dest.parent.mkdir()
    outputs = Outputs((str(dest),), "json", [str(source)])
    res = build_file(str(source), OPTIONS)
    stage(res, str(dest), outputs)
    assert res.staged is not None
    dest.symlink_to(source)
    with pytest.raises(AouError) as err:
        name(str(dest), res, outputs.reads)
    assert [d.code for d in err.value.diagnostics] == ["I502"]
    assert source.read_bytes() == before
    assert [p.name for p in dest.parent.iterdir()] == ["hesitant.json"]  # the link only
    assert dest.is_symlink()


def test_an_output_onto_an_input_is_refused_under_jobs_before_any_work(tmp_path):
    """``-o`` naming a folder where an input's output would be a link to another input:
    refused before any build, nothing written, the input as it was."""
    from aou_dsl.cli.commands import main

    src = tmp_path / "in"
    src.mkdir()
    for n in _FOUR:
        shutil.copy(BEHAVIOURS / f"{n}.aou", src / f"{n}.aou")
    before = (src / "curious.aou").read_bytes()
    out = tmp_path / "out"
    out.mkdir()
    (out / "hesitant.json").symlink_to(src / "curious.aou")
    assert main(["compile", *(str(src / f"{n}.aou") for n in _FOUR), "-o", f"{out}/",
                 "--jobs", "2", "--rate", "100"]) != 0
    assert (src / "curious.aou").read_bytes() == before
    assert sorted(p.name for p in out.iterdir()) == ["hesitant.json"]


class _Recorder:
    """A pool that records what it is handed and finishes nothing by itself."""

    def __init__(self):
        from concurrent.futures import Future

        self.started = [Future()]
        self.handed: list[tuple[str, ...]] = []
        self.futures: list = []
        self._future = Future

    def submit(self, fn, lints, *args):
        self.handed.append(tuple(lint.path for lint in lints))
        f = self._future()
        self.futures.append(f)
        return f


def test_a_warm_worker_holds_two_groups_the_longest_first(tmp_path):
    """The worker always has its next group waiting while it builds one: two at its
    start, one more as each comes back, longest first; this process takes the
    shortest."""
    names = ("hesitant", "curious", "inactive", "confident", "fearful")
    paths = []
    for name in names:
        shutil.copy(BEHAVIOURS / f"{name}.aou", tmp_path / f"{name}.aou")
        paths.append(str(tmp_path / f"{name}.aou"))
    lints = [lint_file(p) for p in paths]
    groups = batch._groups(lints)
    recorder = _Recorder()
    queue = batch._Queue(lints, groups, OPTIONS, None, recorder)
    queue.start()
    assert recorder.handed == []  # not before the worker is warm
    recorder.started[0].set_result(1234)
    longest = [tuple(paths[k] for k in g) for g in groups]
    assert recorder.handed == longest[:2]
    assert queue.shortest() == groups[-1]  # this process builds from the other end
    recorder.futures[0].set_result([])
    assert recorder.handed == longest[:3]
    recorder.futures[1].set_result([])
    recorder.futures[2].set_result([])
    assert recorder.handed == longest[:4]  # the fifth was taken here


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="pipe sizes are Linux's")
def test_the_pool_gives_its_results_a_megabyte_of_pipe():
    """A worker writes a result (about a megabyte for hesitant) whole before it takes its
    next file: through a pipe of 64 KiB it waited for this process to read each part."""
    import fcntl

    with pool.BuildPool(1, robots=(), options=OPTIONS) as p:
        writer = p._pool._result_queue._writer
        assert fcntl.fcntl(writer.fileno(), fcntl.F_GETPIPE_SZ) >= pool._RESULT_PIPE
