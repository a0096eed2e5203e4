"""The jsPsych a built study runs on: pinned versions, their files and integrity hashes.

jsPsych (npm ``jspsych``) and its plugins are not part of aou. A built study loads them
either from a CDN (jsDelivr serves npm packages' files byte for byte), each ``<script>``
carrying the file's Subresource Integrity hash so that a changed file is refused by the
browser, or from a local install copied into the study (``--jspsych DIR``: a
``node_modules`` folder of ``npm install jspsych@8.3.0 @jspsych/plugin-...``), which then
runs with no network. The hashes here were computed from the npm packages' files (sha384
of each, base64) and are checked against a local install before it is copied.
"""

from __future__ import annotations

import base64
import hashlib
import os
import shutil

from ..core.codes import I501
from ..core.diagnostics import AouError, Span, diag

__all__ = ["CDN", "FILES", "PACKAGES", "copy_local", "sri"]

#: The npm packages and versions a built study needs.
PACKAGES = {
    "jspsych": "8.3.0",
    "@jspsych/plugin-html-button-response": "2.1.0",
    "@jspsych/plugin-survey-html-form": "2.1.0",
}
#: (package, file in the package, its sha384 in Subresource Integrity form).
FILES = (
    ("jspsych", "css/jspsych.css",
     "sha384-+gGUkbtw2BJWSroKW2jzIEXGe7KxdycJ0Bo+CqzpIOSBHOYEHHRWETaV+v2mpdWX"),
    ("jspsych", "dist/index.browser.min.js",
     "sha384-PPMNzYQfqrWFhrOxhpwxXmKK+LDH//fBCLsvA/JIRHOfiuOcZ2j8wJhqo87V4R4B"),
    ("@jspsych/plugin-html-button-response", "dist/index.browser.min.js",
     "sha384-tPGtXEC8xEbInWvarnxvJ3fyzeXwRDS0QjGUts+TGQ9I8OCxiqsv9lxTS3mEN6um"),
    ("@jspsych/plugin-survey-html-form", "dist/index.browser.min.js",
     "sha384-60fiNESvg3n32x9sx0QAOyIlVkUgaC20Fsuo/ROTm0DeXCwEfaJ0FfE674kO0F9n"),
)
#: Where the page loads them from by default.
CDN = "https://cdn.jsdelivr.net/npm/"


def sri(data: bytes) -> str:
    """The Subresource Integrity value of ``data`` (sha384, base64)."""
    return "sha384-" + base64.b64encode(hashlib.sha384(data).digest()).decode()


def urls(local: bool) -> list[tuple[str, str]]:
    """(URL, integrity) of each file, in the order the page loads them: from the CDN at
    the pinned version, or from the study's own ``jspsych/`` folder."""
    out = []
    for pkg, path, integrity in FILES:
        base = f"jspsych/{pkg}/" if local else f"{CDN}{pkg}@{PACKAGES[pkg]}/"
        out.append((base + path, integrity))
    return out


def copy_local(node_modules: str, folder: str) -> list[str]:
    """Copy the pinned files of a local install (``node_modules``, or the folder holding
    it) into ``folder/jspsych/``, each checked against its hash first; the paths copied.

    Raises:
        AouError: I501 when a file is missing or is not the pinned version's.
    """
    root = node_modules
    if os.path.isdir(os.path.join(root, "node_modules")):
        root = os.path.join(root, "node_modules")
    where = Span.whole_file(node_modules)
    checked = []
    for pkg, path, integrity in FILES:
        src = os.path.join(root, *pkg.split("/"), *path.split("/"))
        try:
            with open(src, "rb") as fh:
                data = fh.read(20_000_000)
        except OSError as exc:
            raise AouError(diag(I501, f"--jspsych: cannot read {pkg}'s {path} in "
                                f"`{node_modules}` ({exc.strerror}); install it with npm "
                                f"install {' '.join(f'{k}@{v}' for k, v in PACKAGES.items())}",
                                where)) from None
        if sri(data) != integrity:
            raise AouError(diag(I501, f"--jspsych: {pkg}'s {path} in `{node_modules}` is "
                                f"not version {PACKAGES[pkg]}'s (its hash differs)", where))
        checked.append((src, pkg, path))
    out = []
    for src, pkg, path in checked:
        dst = os.path.join(folder, "jspsych", *pkg.split("/"), *path.split("/"))
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        shutil.copyfile(src, dst)
        out.append(dst)
    return out
