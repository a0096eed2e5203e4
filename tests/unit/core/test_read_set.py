"""The output rule over a batch of many inputs: the same refusals as asking every input in
turn, and a look-up per output, not a pass over the inputs.

The reference below is the rule as its definition states it, one input at a time: an
output is refused for the first input (in the order given) whose resolved path is the
output's (``is`` when the two paths are spelt alike once made absolute, ``links to``
otherwise) or that is the same file as the output (a hard link); a bag is refused for
the first input its folder holds.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import pytest

from aou_dsl.cli.outputs import guard_outputs
from aou_dsl.core.diagnostics import AouError
from aou_dsl.core.files import guard_output
from aou_dsl.core.read_set import ReadSet

#: Inputs in a batch: enough that asking every input for every output is a quarter of a
#: million questions, few enough to make on any file system in a moment.
N = 500


def _reference(path: str, reads: list[str]) -> tuple[str, str] | None:
    """(how, read) of the first input ``path`` would write over, read by read."""
    for read in reads:
        try:
            if os.path.realpath(path) == os.path.realpath(read):
                same = os.path.abspath(path) == os.path.abspath(read)
                return ("is" if same else "links to"), read
            if os.path.exists(path) and os.path.exists(read) and os.path.samefile(path, read):
                return "is a hard link of", read
        except (OSError, ValueError):
            continue
    return None


def _batch(root: Path) -> list[str]:
    """N inputs in nested folders, some listed twice, some by a linked folder."""
    reads = []
    for i in range(N):
        folder = root / "in" / f"d{i % 7}"
        folder.mkdir(parents=True, exist_ok=True)
        f = folder / f"b{i}.aou"
        f.write_text(f"behaviour b{i} : confident\napproach\n")
        reads.append(str(f))
    (root / "linked").symlink_to(root / "in" / "d3")
    reads.append(str(root / "linked" / "b10.aou"))  # b10 again, by the linked folder
    reads.append(reads[5])  # listed twice
    return reads


def _cases(root: Path, reads: list[str]) -> list[str]:
    """Outputs that clash with inputs early, late and in the middle of the batch, in
    every way the rule names, and outputs that clash with none."""
    out = root / "out"
    out.mkdir()
    cases = [reads[0], reads[N - 1], reads[N // 2]]  # the input itself
    cases.append(str(root / "in" / "d3" / ".." / "d3" / "b10.aou"))  # another spelling
    cases.append(os.path.relpath(reads[N - 2]))  # relative to the working folder
    for i in (1, N // 3, N - 3):
        link = out / f"sym{i}.json"
        link.symlink_to(reads[i])  # a symbolic link to an input
        cases.append(str(link))
        hard = out / f"hard{i}.json"
        os.link(reads[i], hard)  # a hard link of an input
        cases.append(str(hard))
    cases.append(str(root / "linked" / "b17.aou"))  # an input, through a linked folder
    chain = out / "chain.json"
    chain.symlink_to(out / f"sym{N // 3}.json")  # a link to a link to an input
    cases.append(str(chain))
    (out / "dangling.json").symlink_to(out / "nowhere.json")
    cases += [str(out / "dangling.json"), str(out / "new.json"), str(root / "in" / "d1")]
    for i in range(40):
        cases.append(str(out / f"fresh{i}.json"))
    return cases


def _refusal(path: str, reads, **kw) -> tuple[str, str, str | None] | None:
    try:
        guard_output(path, reads, **kw)
    except AouError as err:
        d = err.diagnostics[0]
        return str(d.code), d.message, d.hint
    return None


def test_every_refusal_is_the_one_asking_each_input_finds(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    reads = _batch(tmp_path)
    cases = _cases(tmp_path, reads)
    _, _, indexed = guard_outputs(_args(None), [(r, None) for r in reads[:2]], reads)
    refused = 0
    for path in cases:
        want = _reference(path, reads)
        got = _refusal(path, indexed)
        assert _refusal(path, reads) == got  # a plain list: the same answer
        if want is None:
            assert got is None or "folder" in got[1], path  # d1 is a folder, not an input
            continue
        refused += 1
        how, read = want
        assert got == ("I502", f"refusing to write `{path}`: it {how} `{read}`, which this "
                       "command reads", "choose another output with -o"), path
    assert refused == 13  # every clash above was refused, none let through


def test_a_bag_is_refused_for_the_first_input_it_holds(tmp_path):
    reads = _batch(tmp_path)
    _, _, indexed = guard_outputs(_args(None), [(r, None) for r in reads[:2]], reads)
    for folder, first in ((tmp_path / "in", reads[0]), (tmp_path / "in" / "d3", reads[3]),
                          (tmp_path / "linked", reads[3])):
        got = _refusal(str(folder), indexed, bag=True)
        assert got is not None and got[1] == (
            f"refusing to write the bag `{folder}`: it holds `{first}`, which this "
            "command reads"), folder
    # a folder beside the inputs whose name starts like theirs holds none of them
    (tmp_path / "in" / "d3x").mkdir()
    assert _refusal(str(tmp_path / "in" / "d3x"), indexed, bag=True) is None


def _args(output: str | None) -> argparse.Namespace:
    return argparse.Namespace(no_output=False, output=output, format=None,
                              write_fitted=None, sarif=None)


def test_a_batch_asks_the_file_system_about_each_file_a_bounded_number_of_times(
        tmp_path, monkeypatch):
    """Counted, not timed: the rule over N outputs, before the work and again as each is
    written, resolves paths a bounded number of times per file, not once per pair."""
    reads = _batch(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    calls = {"realpath": 0, "stat": 0}
    realpath, stat = os.path.realpath, os.stat

    def counted_realpath(p, *a, **k):
        calls["realpath"] += 1
        return realpath(p, *a, **k)

    def counted_stat(p, *a, **k):
        calls["stat"] += 1
        return stat(p, *a, **k)

    monkeypatch.setattr(os.path, "realpath", counted_realpath)
    monkeypatch.setattr(os, "stat", counted_stat)
    inputs = [(r, None) for r in reads[:N]]
    checked = guard_outputs(_args(str(out) + os.sep), inputs, reads)  # before the work
    assert max(calls.values()) <= 12 * N, calls
    for dest in checked[0]:  # as each output is written, with the reads it gave back
        assert dest is not None
        guard_output(dest, checked[2])
    assert max(calls.values()) <= 16 * N, calls


if __name__ == "__main__":
    pytest.main([__file__, "-q"])


def test_a_pickled_set_keeps_the_identities_taken_before_any_work(tmp_path):
    """A worker gets the set pickled: it answers as the command's own set does, from
    the identities taken when the set was made (an input removed since, whose bytes
    another name now holds, still refuses that name as its hard link)."""
    import pickle

    a, b = tmp_path / "a.aou", tmp_path / "b.aou"
    a.write_text("x")
    b.write_text("y")
    (tmp_path / "link.json").symlink_to(a)
    reads = ReadSet([str(a), str(b)])
    os.link(b, tmp_path / "held.json")
    b.unlink()
    back = pickle.loads(pickle.dumps(reads))
    assert isinstance(back, ReadSet) and tuple(back) == tuple(reads)
    for path in (a, b, tmp_path / "link.json", tmp_path / "held.json", tmp_path / "new"):
        assert back.clash(str(path)) == reads.clash(str(path)), path
    assert back.clash(str(tmp_path / "held.json")) == ("is a hard link of", str(b))
