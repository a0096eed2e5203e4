"""``aouc``'s parser is made once per process and reused: a command run after another
gets nothing of the one before (an appending option starts from its own default)."""

from __future__ import annotations

from aou_dsl.cli import args, commands


def test_commands_of_one_process_share_one_parser(monkeypatch, capsys):
    made: list[int] = []
    real = args.build_parser

    def counting():
        made.append(1)
        return real()

    monkeypatch.setattr(args, "build_parser", counting)
    args.shared_parser.cache_clear()
    for _ in range(3):
        assert commands.main(["rules", "S001"]) == 0
    assert made == [1]
    args.shared_parser.cache_clear()


def test_a_parse_leaves_nothing_for_the_next():
    parser, _ = args.shared_parser()
    first, _ = parser.parse_known_args(["compile", "a.aou", "--package-dir", "/x",
                                        "--package-dir", "/y"])
    again, _ = parser.parse_known_args(["compile", "b.aou"])
    assert first.package_dir == ["/x", "/y"]
    assert again.package_dir == [] and again.paths == ["b.aou"]
    pins, _ = parser.parse_known_args(["dmp", "roll", "b.dmp", "--pin",
                                       "approach"])
    assert parser.parse_known_args(["dmp", "roll", "b.dmp"])[0].pin == []
    assert pins.pin == ["approach"]
