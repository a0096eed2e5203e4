"""Tampered ``.dmp`` folders, generated from what the format promises, and a runner that
reads each with aou in a child process and counts what must never happen.

The promises (docs/dmp.md, "A .dmp folder is untrusted input"): every field of the
manifest and of a part file has a type, a range and a size; names exist in the arm; a
part path stays inside its folder; a part file names only ``CartesianDMP`` (and its
``ForcingTerm``s), and nothing named in a file is imported. The generator breaks one
promise (or several) at a time, at a random place in a real folder written by
``aouc compile --format dmp``:

- types: a value becomes a number, a string, a list, an object, null or a boolean;
- values: 0, negatives, NaN, infinities, huge and tiny numbers, huge integers;
- sizes: lists emptied, cut, grown, nested; a part listed many times; long strings;
- names: unknown robots, frames and joints, robot files outside, paths with ``..``,
  absolute paths, empty names;
- module/class: a part (or a forcing term) naming ``subprocess.getoutput``,
  ``os.system``, ``builtins.exec``... with an argument that would create the canary
  file.

The runner (``python -m tests.dmpgen BASE SEED COUNT OUT``) reads every case with
``read_dmp`` and rolls out those it accepts, in one process the test runs under a
timeout: a case that hangs shows as the last one started. It reports, per case, the
outcome (a code, or ``read``) and counts internal errors (any exception but aou's
coded ones), inputs changed (a file's bytes before and after) and the canary.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import os
import random
import shutil
import sys
from typing import Any

#: Where the runner's payloads would write if code named in a file ran.
CANARY_NAME = "CANARY"

_NUMBERS = [0, -1, -1e-9, 1e-300, 1e300, 10 ** 400, -10 ** 30, math.nan, math.inf,
            -math.inf, 0.5, 2, 1e6, -0.001, 123456789]
_NAMES = ["", "nope", "panda_joint99", "/etc/passwd", "../outside.json",
          "/dev/zero", "x" * 5000, "parts/../manifest.json", "panda", "ur5", "tool0",
          "arm.toml", "/dev/zero.urdf", "\u0000", "panda_link8"]


def _payloads(canary: str) -> list[dict[str, Any]]:
    """Part files naming a module and class that would create ``canary`` if imported and
    called as the library's ``read_json`` does."""
    cmd = f"touch {canary}"
    return [{"module": "subprocess", "class": "getoutput", "cmd": cmd},
            {"module": "subprocess", "class": "check_output", "args": ["touch", canary]},
            {"module": "os", "class": "system", "command": cmd},
            {"module": "builtins", "class": "exec", "source": f"open({canary!r}, 'w')"},
            {"module": "pathlib", "class": "Path", "args": canary},
            {"module": "movement_primitives.io", "class": "write_json",
             "filename": canary, "obj": 1},
            {"module": "movement_primitives.dmp", "class": "DMP", "n_dims": 3},
            {"module": "movement_primitives.dmp._cartesian_dmp", "class": "CartesianDMP",
             "__class__": {"module": "os", "class": "system", "command": cmd}}]


def _values(rng: random.Random, canary: str) -> Any:
    """A value of some category: a wrong type, a bad number, a size, a name."""
    pick = rng.randrange(6)
    if pick == 0:
        return rng.choice(_NUMBERS)
    if pick == 1:
        return rng.choice(_NAMES)
    if pick == 2:
        return rng.choice([None, True, False, {}, [], {"a": 1}, [1, 2, 3], [[1.0] * 3] * 2,
                           "0.5", [math.nan] * 3])
    if pick == 3:
        n = rng.choice([0, 1, 2, 6, 8, 1000, 200_000])
        return [rng.choice([0.0, 1.0, -1.0])] * n
    if pick == 4:  # nested lists, spelt out when the document is written (_dump)
        return f"__DEEP_{rng.choice([10, 100, 5000, 100_000])}__"
    return rng.choice(_payloads(canary))


def _paths(doc: Any, prefix: tuple = (), depth: int = 0) -> list[tuple]:
    """Every path into ``doc`` (keys and indexes), long lists sampled."""
    out = [prefix]
    if depth > 6:
        return out
    if isinstance(doc, dict):
        for k, v in doc.items():
            out += _paths(v, (*prefix, k), depth + 1)
    elif isinstance(doc, list):
        idx = range(len(doc)) if len(doc) <= 8 else [0, 1, len(doc) // 2, len(doc) - 1]
        for i in idx:
            out += _paths(doc[i], (*prefix, i), depth + 1)
    return out


def _set(doc: Any, path: tuple, value: Any) -> Any:
    if not path:
        return value
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return doc


def _delete(doc: Any, path: tuple) -> Any:
    node = doc
    for k in path[:-1]:
        node = node[k]
    if isinstance(node, dict):
        node.pop(path[-1], None)
    elif isinstance(node, list) and node:
        node.pop(path[-1])
    return doc


def mutate(rng: random.Random, manifest: dict, parts: dict[str, Any], canary: str
           ) -> tuple[dict, dict[str, Any], str]:
    """One tampered folder: the manifest, the part files (name -> document, or raw text
    under a ``str`` value) and what was done."""
    m, p = copy.deepcopy(manifest), dict(parts)
    what = []
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        try:
            _mutate_once(rng, m, p, canary, what)
        except (TypeError, KeyError, IndexError, AttributeError):
            what.append("(a later change found the earlier one in its way)")
    if rng.random() < 0.05:
        m["extra"] = {"module": "os", "class": "system", "command": f"touch {canary}"}
        what.append("manifest extra field")
    return m, p, "; ".join(what)


def _mutate_once(rng: random.Random, m: dict, p: dict[str, Any], canary: str,
                 what: list[str]) -> None:
    """Break one promise of the folder ``m`` (manifest), ``p`` (parts), noting it."""
    target = rng.random()
    if target < 0.1:  # a value inside its promised range: read, then rolled out
        _in_range(rng, m, p, what)
    elif target < 0.16:  # parts listed many times
        n = rng.choice([2, 10, 1000, 5000])
        m["parts"] = m["parts"] * max(1, min(n, 20_000 // max(1, len(m["parts"]))))
        what.append(f"parts x{n}")
    elif target < 0.22:  # a part file's path leaves the folder
        i = rng.choice([k for k, e in enumerate(m["parts"]) if e["file"]])
        m["parts"][i]["file"] = rng.choice(["../outside.json", "/tmp/x.json",
                                            "parts/../../outside.json", "parts/",
                                            "parts/missing.json", "manifest.json",
                                            "parts//01-approach.json", "."])
        what.append(f"parts[{i}].file -> {m['parts'][i]['file']}")
    elif target < 0.32:  # a part names a module and class
        name = rng.choice(sorted(p))
        payload = rng.choice(_payloads(canary))
        if rng.random() < 0.5:
            doc = copy.deepcopy(p[name])
            if rng.random() < 0.5:
                doc[rng.choice(["forcing_term_pos", "forcing_term_rot"])] = payload
            doc.update({k: v for k, v in payload.items() if rng.random() < 0.5})
            p[name] = doc
        else:
            p[name] = payload
        what.append(f"{name} names {payload['module']}.{payload['class']}")
    elif target < 0.66:  # a manifest field
        path = rng.choice(_paths(m)[1:])
        if rng.random() < 0.15:
            _delete(m, path)
            what.append(f"manifest {path} deleted")
        else:
            value = _values(rng, canary)
            _set(m, path, value)
            what.append(f"manifest {path} -> {str(value)[:60]}")
    else:  # a part file field
        name = rng.choice(sorted(p))
        doc = copy.deepcopy(p[name])
        path = rng.choice(_paths(doc)[1:])
        if rng.random() < 0.1:
            _delete(doc, path)
            what.append(f"{name} {path} deleted")
        else:
            value = _values(rng, canary)
            _set(doc, path, value)
            what.append(f"{name} {path} -> {str(value)[:60]}")
        p[name] = doc


def _in_range(rng: random.Random, m: dict, p: dict[str, Any], what: list[str]) -> None:
    """A field given a value the format allows (its ends included)."""
    i = rng.randrange(len(m["parts"]))
    name = rng.choice(sorted(p))
    choices = [
        (m, ("rate",), rng.choice([1, 7.5, 1000])),
        (m, ("intensity",), rng.choice([0, 1, rng.random()])),
        (m, ("state",), rng.choice([None, "confident", "inactive"])),
        (m, ("parts", i, "duration"), rng.choice([0.0, rng.uniform(0, 5)])),
        (m, ("parts", i, "lead"), rng.uniform(-1, 1)),
        (p, (name, "int_dt"), rng.choice([1e-4, 1e-2])),
        (p, (name, "smooth_scaling"), True),
        (p, (name, "alpha_y", rng.randrange(6)), rng.choice([1e-3, 100.0])),
        (p, (name, "_execution_time"), rng.uniform(0.05, 10))]
    doc, path, value = rng.choice(choices)
    if doc is p:
        p[path[0]] = copy.deepcopy(p[path[0]])
    _set(doc, path, value)
    what.append(f"in range: {path} -> {value}")


def _digest(folder: str) -> dict[str, str]:
    out = {}
    for root, _, files in os.walk(folder):
        for f in files:
            path = os.path.join(root, f)
            if os.path.isfile(path) and not os.path.islink(path):
                with open(path, "rb") as fh:
                    out[os.path.relpath(path, folder)] = hashlib.sha256(fh.read()).hexdigest()
    return out


def _dump(doc: Any) -> str:
    """``doc`` as JSON (NaN and infinities as Python writes them), nested lists spelt
    out where :func:`_values` left their marker."""
    text = json.dumps(doc)
    for n in (10, 100, 5000, 100_000):
        text = text.replace(f'"__DEEP_{n}__"', "[" * n + "1" + "]" * n)
    return text


def write_case(folder: str, base: str, manifest: dict, parts: dict[str, Any]) -> None:
    """The tampered folder: the manifest and every part written, the untouched parts
    linked (hard links: a write into them would show in the base folder too)."""
    os.makedirs(os.path.join(folder, "parts"))
    with open(os.path.join(folder, "manifest.json"), "w") as fh:
        fh.write(_dump(manifest))
    for name, doc in parts.items():
        target = os.path.join(folder, name)
        if doc is _BASE:
            os.link(os.path.join(base, name), target)
        else:
            with open(target, "w") as fh:
                fh.write(_dump(doc))


_BASE = object()


def load_base(base: str) -> tuple[dict, dict[str, Any]]:
    with open(os.path.join(base, "manifest.json")) as fh:
        manifest = json.load(fh)
    parts = {}
    for e in manifest["parts"]:
        if e["file"]:
            with open(os.path.join(base, e["file"])) as fh:
                parts[e["file"]] = json.load(fh)
    return manifest, parts


def run(base: str, seed: int, count: int, out: str, solve: bool = False) -> dict[str, Any]:
    """Read ``count`` tampered folders (seeded), roll out those read; the counts."""
    import numpy as np

    from aou_dsl.core.diagnostics import AouError
    from aou_dsl.dmp import read_dmp, roll
    from aou_dsl.dmp import solve as solve_seq

    rng = random.Random(seed)
    manifest, parts = load_base(base)
    before_base = _digest(base)
    work = os.path.join(out, "cases")
    canary = os.path.join(out, CANARY_NAME)
    with open(os.path.join(out, "outside.json"), "w") as fh:
        json.dump(parts[sorted(parts)[0]], fh)  # what a path leaving the folder would find
    result: dict[str, Any] = {"cases": 0, "internal": [], "changed": [], "codes": {},
                              "read": 0, "canary": False}
    progress = os.path.join(out, "progress")
    for k in range(count):
        m, p, what = mutate(rng, manifest, parts, canary)
        untouched = {n: (_BASE if p[n] is parts[n] else p[n]) for n in p}
        folder = os.path.join(work, f"c{k}.dmp")
        write_case(folder, base, m, untouched)
        with open(progress, "w") as fh:
            fh.write(f"{k}: {what}\n")
        before = _digest(folder)
        try:
            with np.errstate(all="raise"):  # a numeric warning is a missed check too
                seq = read_dmp(folder)
                outcome = "read"
                result["read"] += 1
                if solve:
                    solve_seq(seq, path=folder)
                else:
                    roll(seq)
        except AouError as err:
            outcome = err.diagnostics[0].code
        except Exception as exc:  # noqa: BLE001 - what the suite counts
            outcome = "internal"
            result["internal"].append(f"{what}: {type(exc).__name__}: {exc}"[:400])
        result["codes"][outcome] = result["codes"].get(outcome, 0) + 1
        if _digest(folder) != before:
            result["changed"].append(what)
        shutil.rmtree(folder)
        result["cases"] += 1
        if os.path.exists(canary):
            result["canary"] = True
            break
    if _digest(base) != before_base:
        result["changed"].append("the base folder")
    return result


if __name__ == "__main__":
    base_, seed_, count_, out_ = sys.argv[1:5]
    res = run(base_, int(seed_), int(count_), out_, solve=len(sys.argv) > 5)
    print(json.dumps(res))
