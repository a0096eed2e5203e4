"""Helpers of the tests that drive aou from outside: a browser, a page, a server."""


def find_chromium() -> str | None:
    """The Chromium the browser tests drive: the one ``AOU_CHROMIUM`` names, else
    Debian's (None: none is installed)."""
    import os
    import shutil

    return next((p for p in (os.environ.get("AOU_CHROMIUM"), shutil.which("chromium"),
                             "/usr/bin/chromium") if p and os.path.exists(p)), None)


def wait_for(what, timeout: float = 90.0, every: float = 0.1):
    """Poll ``what()`` until it is truthy and give its value; the test fails on timeout
    (a page, a server or a loop that never gets there). Tests of live things wait on a
    condition this way, never on a fixed sleep."""
    import time

    end = time.monotonic() + timeout
    while time.monotonic() < end:
        got = what()
        if got:
            return got
        time.sleep(every)
    raise AssertionError("timed out waiting for the page")
