"""Many builds at once: a pool of worker processes and a Dask cluster give, for every
input, exactly what building it alone gives, in the order of the inputs."""

import pytest

from aou_dsl.build.builder import build_file
from aou_dsl.build.parallel import BuildPool, build_many, encoded, write_result
from aou_dsl.compiler.output import encode

from .conftest import BEHAVIOURS, INVALID

#: Valid behaviours, a file that does not exist and an invalid one, interleaved, so that
#: results finish out of order (the long hesitant first) and failures sit in between.
INPUTS = [str(BEHAVIOURS / "hesitant.aou"), str(BEHAVIOURS / "confident.aou"),
          "no/such/file.aou", str(INVALID / "invalid_bad_character.aou"),
          str(BEHAVIOURS / "inactive.aou")]
OPTIONS = {"rate": 100.0}


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
    return [build_file(p, **OPTIONS) for p in INPUTS]


@pytest.mark.slow
def test_a_pool_of_workers_gives_what_each_build_alone_gives(alone):
    _same(list(build_many(INPUTS, OPTIONS, jobs=2)), alone)


@pytest.mark.slow
def test_a_pool_stays_warm_across_maps(alone, tmp_path):
    """The second map is longer than one window of files handed out (longest motion
    first), and has the workers encode the documents: the bytes written are those of
    encoding the document built alone."""
    with BuildPool(2) as pool:
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
