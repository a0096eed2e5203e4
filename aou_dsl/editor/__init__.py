"""``aouc server``: a language server for ``.aou`` files, over stdio.

Diagnostics as you type (``aouc lint``'s), compile diagnostics after a save or a pause
in typing (``aouc compile``'s, in a worker thread: typing never waits for them), hover,
completion, quick fixes, formatting (``aouc fmt``) and document symbols.

The server needs the ``lsp`` extra (pygls, lsprotocol); nothing here imports them until
the server starts, so ``import aou_dsl`` and ``aouc lint`` stay light. All access to
the pipeline goes through :mod:`aou_dsl.editor.lsp_engine`.
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["cmd_server"]


def cmd_server(args: argparse.Namespace) -> int:
    """``aouc server``: serve the Language Server Protocol on stdin and stdout until
    the editor says exit. 2 when the ``lsp`` extra is missing, 130 on Ctrl-C."""
    try:
        import lsprotocol  # noqa: F401
        import pygls  # noqa: F401
    except ImportError as exc:
        print(f"aouc: this command needs the lsp extra ({exc.name} is missing): "
              "pip install '.[lsp]' in aou's folder (the one with pyproject.toml)",
              file=sys.stderr)
        return 2
    from .server import serve

    return serve(robot=getattr(args, "robot", None))
