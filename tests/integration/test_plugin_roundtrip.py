"""The round trip with the test plugin installed: generated behaviours that use
``anticipate`` (tests/plugins/anticipate_gen.py, whose expected descriptors come from the
definitions) compile, and ``aouc measure`` reads back what each declares."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.plugins.anticipate_gen import generate
from tests.plugins.install import for_commands

AOUC = [sys.executable, "-m", "aou_dsl"]

#: Matched within the descriptors' own tolerances: counts exactly, distances to 1 mm,
#: durations 2 % or 20 ms, accelerations 3 %.
TOLERANCE = {"anticipate_count": 0, "anticipate_distance": 1e-3, "pause_count": 0,
             "retreat_count": 0, "retreat_distance": 1e-3}
RELATIVE = {"pause_duration": (0.02, 0.02), "approach_acceleration": (0.03, 0.0),
            "retreat_acceleration": (0.03, 0.0)}


def _close(name: str, want: float | int | None, got: float | int | None) -> bool:
    if want is None or got is None:
        return want is None and got is None
    if name in RELATIVE:
        rel, absolute = RELATIVE[name]
        return abs(got - want) <= max(absolute, rel * abs(want)) + 1e-9
    return abs(got - want) <= TOLERANCE[name] + 1e-9


def _round_trip(seeds: range, tmp_path) -> None:
    files = []
    for seed in seeds:
        g = generate(seed)
        path = tmp_path / f"gen{seed}.aou"
        path.write_text(g.text, encoding="utf-8")
        files.append((path, g))
    env = for_commands(tmp_path).env
    out = tmp_path / "out"
    run = subprocess.run([*AOUC, "compile", *(str(p) for p, _ in files), "-o",
                          str(out)], capture_output=True, text=True, env=env,
                         timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    for path, g in files:
        traj = out / f"{path.stem}.json"
        run = subprocess.run([*AOUC, "measure", str(traj), "--against", str(path),
                              "--format", "json"], capture_output=True, text=True,
                             env=env, timeout=300)
        assert run.returncode == 0, f"{g.text}\n{run.stdout}{run.stderr}"
        rows = {r["descriptor"]: r for r in json.loads(run.stdout)["descriptors"]}
        wrong = {name: (want, rows[name]["declared"], rows[name]["measured"])
                 for name, want in g.expected.items()
                 if not (_close(name, want, rows[name]["declared"])
                         and _close(name, want, rows[name]["measured"]))}
        assert not wrong, f"{g.text}\n{wrong}"


def test_generated_files_using_the_plugin_measure_as_declared(tmp_path):
    _round_trip(range(3), tmp_path)


@pytest.mark.slow
def test_more_generated_files_using_the_plugin_measure_as_declared(tmp_path):
    _round_trip(range(3, 23), tmp_path)


def test_the_generator_declares_what_the_definitions_say():
    """The generator's expectations hold on its own text: every anticipation comes
    directly before an approach, every retreat between two pauses, no two pauses touch,
    and its counts are the statements'."""
    for seed in range(50):
        g = generate(seed)
        body = [ln.split()[0] for ln in g.text.splitlines()[5:-1]]
        for i, word in enumerate(body):
            if word == "anticipate":
                assert body[i + 1] == "approach"
            if word == "retreat":
                assert body[i - 1] == body[i + 1] == "pause"
            if word == "pause" and i + 1 < len(body):
                assert body[i + 1] != "pause"
        assert g.expected["anticipate_count"] == body.count("anticipate")
        assert g.expected["retreat_count"] == body.count("retreat")
        assert g.expected["pause_count"] == body.count("pause")
