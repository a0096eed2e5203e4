"""The loader looks for the ``aou.kinds`` section in the installed distributions'
``entry_points.txt`` before it imports importlib.metadata: the look must find every
declaring distribution, and only those."""

from __future__ import annotations

import subprocess
import sys
import zipfile

from aou_dsl.core.plugins import _declared


def _dist(site, name, entry_points: str | None):
    info = site / f"{name}-1.0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 1.0\n")
    if entry_points is not None:
        (info / "entry_points.txt").write_text(entry_points)


def test_only_a_distribution_with_the_section_counts(tmp_path):
    site = tmp_path / "site"
    _dist(site, "tool", "[console_scripts]\ntool = tool:main\n")
    _dist(site, "bare", None)
    (site / "old.egg-info").write_text("Name: old\n")  # an egg-info that is a file
    path = (str(tmp_path / "absent"), str(site))
    assert not _declared(path)
    _dist(site, "kinds", "[console_scripts]\nk = k:main\n\n[ aou.kinds ]\nnod = nod:plugin\n")
    assert _declared(path)


def test_a_zip_on_the_path_is_looked_into(tmp_path):
    empty, kinds, broken = (tmp_path / n for n in ("empty.zip", "kinds.zip", "bad.zip"))
    with zipfile.ZipFile(empty, "w") as z:
        z.writestr("tool-1.0.dist-info/entry_points.txt", "[console_scripts]\nt = t:m\n")
    with zipfile.ZipFile(kinds, "w") as z:
        z.writestr("nod-1.0.dist-info/entry_points.txt", "[aou.kinds]\nnod = nod:plugin\n")
    broken.write_bytes(b"not a zip")
    assert not _declared((str(empty),))
    assert _declared((str(empty), str(kinds)))
    assert _declared((str(broken),))  # unreadable: importlib.metadata decides


def test_lint_without_plugins_does_not_import_importlib_metadata():
    code = ("import sys\nfrom aou_dsl.lang.linter import lint_source\n"
            "lint_source('behaviour b\\nrobot ur5\\nretreat 2cm\\n')\n"
            "print('importlib.metadata' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "False"
