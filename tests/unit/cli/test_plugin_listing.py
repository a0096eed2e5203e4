"""``aouc rules`` and ``aouc robot --list`` name the installed plugins: those loaded,
with the layers they give parts for, and those that cannot be used, with why."""

from __future__ import annotations

import pytest

from aou_dsl.cli.commands import main

from ..fake_plugins import LURCH, fresh_plugins, install  # noqa: F401

pytestmark = pytest.mark.usefixtures("fresh_plugins")


def _run(capsys, *argv: str) -> str:
    assert main(list(argv)) == 0
    return capsys.readouterr().out


def test_without_plugins_the_listings_are_as_before(capsys, monkeypatch):
    monkeypatch.setenv("AOU_NO_PLUGINS", "1")
    rules = _run(capsys, "rules")
    assert "plugin" not in rules.split("K803")[1].split("\n", 1)[1]
    assert "plugins (entry point group" not in _run(capsys, "robot", "--list")


def test_rules_and_robot_list_a_loaded_and_a_broken_plugin(tmp_path, monkeypatch, capsys):
    install(tmp_path / "a", monkeypatch, entry="lurch", module="aou_fake_lurch_l",
            source=LURCH, dist="aou-lurch", version="1.2")
    install(tmp_path / "b", monkeypatch, entry="nod", module="aou_fake_nod",
            source="import aou_fake_no_such_module\n", dist="aou-nod")
    for out in (_run(capsys, "rules"), _run(capsys, "robot", "--list"),
                _run(capsys, "rules", "K801")):
        tail = out[out.index("plugins (entry point group aou.kinds): 1 loaded"):]
        lines = tail.splitlines()
        assert lines[1].split() == ["lurch", "aou-lurch", "1.2", "gives:", "kind,",
                                    "descriptors"]
        assert lines[2] == "plugins that cannot be used as they are: 1"
        assert lines[3].split()[:4] == ["K801", "nod", "aou-nod", "0.1"]
        assert "ModuleNotFoundError" in lines[3] and "aou_fake_no_such_module" in lines[3]
    assert "plugins (entry" not in _run(capsys, "rules", "V101")
