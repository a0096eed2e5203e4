"""Many builds at once: a pool of worker processes and a Dask cluster give, for every
input, exactly what building it alone gives, in the order of the inputs."""

import os
import re
import subprocess
import sys

import pytest

from aou_dsl.compiler.output import encode
from aou_dsl.core.options import BuildOptions
from aou_dsl.driver.builder import build_file
from aou_dsl.driver.parallel import BuildPool, build_many, encoded, write_result
from tests.conftest import BEHAVIOURS, INVALID, ROOT

#: Valid behaviours, a file that does not exist and an invalid one, interleaved, so that
#: results finish out of order (the long hesitant first) and failures sit in between.
INPUTS = [str(BEHAVIOURS / "hesitant.aou"), str(BEHAVIOURS / "confident.aou"),
          "no/such/file.aou", str(INVALID / "invalid_bad_character.aou"),
          str(BEHAVIOURS / "inactive.aou")]
OPTIONS = BuildOptions(rate=100.0)


def _same(got, want) -> None:
    assert [r.path for r in got] == [r.path for r in want] == INPUTS
    for g, w in zip(got, want, strict=True):
        assert g.ok == w.ok
        assert [d.to_json() for d in g.diagnostics] == [d.to_json() for d in w.diagnostics]
        if w.document is None:
            assert g.document is None
        else:
            assert encode(g.document, "json") == encode(w.document, "json")


@pytest.fixture(scope="module")
def alone():
    """Each input built on its own, in this process."""
    return [build_file(p, OPTIONS) for p in INPUTS]


@pytest.mark.slow
def test_a_pool_of_workers_gives_what_each_build_alone_gives(alone):
    _same(list(build_many(INPUTS, OPTIONS, jobs=2)), alone)


@pytest.mark.slow
@pytest.mark.parametrize("start", ["fork", "spawn"])
def test_a_pool_stays_warm_across_maps(alone, tmp_path, start):
    """The second map is longer than one window of files handed out (longest motion
    first), and has the workers encode the documents: the bytes written are those of
    encoding the document built alone. Forked workers (copies of this process, which
    has built before) and fresh ones give the same."""
    from aou_dsl.driver.pool import can_fork

    if start == "fork" and sys.platform.startswith("linux") and not can_fork():
        # This process runs another thread (a pytest-xdist worker's), so a pool here
        # would not fork: the test runs alone in a fresh pytest, where it does.
        test = f"{__file__}::test_a_pool_stays_warm_across_maps[fork]"
        proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p",
                               "no:cacheprovider", test], capture_output=True, text=True,
                              cwd=ROOT, check=False)
        assert proc.returncode == 0 and "1 passed" in proc.stdout, proc.stdout[-3000:]
        return
    with BuildPool(2, start=start) as pool:
        assert pool.start == start or not sys.platform.startswith("linux")
        first = list(pool.map(INPUTS, OPTIONS))
        again = list(build_many(INPUTS * 4, OPTIONS, pool=pool, encode="json"))
    _same(first, alone)
    for k in range(4):
        _same(again[5 * k:5 * k + 5], alone)
    for k, (got, want) in enumerate(zip(again, alone * 4, strict=True)):
        if want.document is None:
            continue
        assert encoded(got, "json") == encode(want.document, "json")
        write_result(str(tmp_path / f"{k}.csv"), got, "csv")  # not the format encoded
        assert (tmp_path / f"{k}.csv").read_bytes() == encode(want.document, "csv")


def test_one_job_builds_here_in_order(alone):
    _same(list(build_many(INPUTS, OPTIONS, jobs=1)), alone)


@pytest.mark.slow
def test_a_dask_cluster_gives_what_each_build_alone_gives(alone):
    """A local cluster of two worker processes on the loopback interface, started here;
    reached once through a client and once through the scheduler's address."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            _same(list(build_many(INPUTS, OPTIONS, cluster=client)), alone)
        _same(list(build_many(INPUTS, OPTIONS, cluster=cluster.scheduler_address)), alone)


def _compile(paths: list[str], jobs: int, out) -> tuple[int, list[str]]:
    """``aouc compile`` of ``paths`` in a fresh process: its exit status and what it
    printed, the compile times left out (they differ from run to run)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, "-m", "aou_dsl", "compile", *paths, "--jobs",
                           str(jobs), "-o", f"{out}/"], cwd=ROOT, env=env,
                          capture_output=True, text=True)
    said = re.sub(r"compiled in [0-9.]+ s", "compiled", proc.stderr).replace(str(out), "OUT")
    return proc.returncode, said.splitlines()


@pytest.mark.slow
def test_a_parallel_compile_writes_and_says_what_one_process_does(tmp_path):
    """``--jobs 2`` (this process and a worker it forks, or spawns) against ``--jobs 1``:
    the same files, byte for byte, the same diagnostics in the same order, the same exit
    status; a file that fails among them included."""
    paths = [str(p) for p in sorted(BEHAVIOURS.glob("*.aou"))]
    paths.insert(2, str(INVALID / "invalid_bad_character.aou"))
    one, two = tmp_path / "one", tmp_path / "two"
    said_one, said_two = _compile(paths, 1, one), _compile(paths, 2, two)
    assert said_two == said_one
    assert said_one[0] != 0 and any("[5/6]" in line for line in said_one[1])
    assert sorted(p.name for p in two.iterdir()) == sorted(p.name for p in one.iterdir())
    assert len(list(one.iterdir())) == 5
    for written in one.iterdir():
        assert (two / written.name).read_bytes() == written.read_bytes()
