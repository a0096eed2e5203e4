"""The JSON Schema files that ship with the package, made from the pydantic models:
``trajectory.schema.json`` (the ``aou-trajectory/1`` document, :class:`.document.Document`)
and ``robot.schema.json`` (a robot description file,
:class:`aou_dsl.robot.toml_model.DescriptionFile`).

Other tools validate aou's files against them without aou. ``python tools/write_schemas.py``
writes them again after a model changes; a test fails while the shipped files differ
from what the models give.
"""

from __future__ import annotations

import json
from importlib import resources
from typing import Any

__all__ = ["SCHEMA_NAMES", "schema", "schema_text", "shipped_text"]

#: The shipped schema files, in ``aou_dsl/schemas/``.
SCHEMA_NAMES = ("trajectory.schema.json", "robot.schema.json")
_DIALECT = "https://json-schema.org/draft/2020-12/schema"


def _without_null(node: Any) -> Any:
    """``node`` with the ``null`` choices pydantic gives optional keys removed (a TOML
    file has no null: a key is there or not)."""
    if isinstance(node, dict):
        any_of = node.get("anyOf")
        if isinstance(any_of, list) and {"type": "null"} in any_of:
            rest = [c for c in any_of if c != {"type": "null"}]
            node = {k: v for k, v in node.items() if k not in ("anyOf", "default")}
            node |= rest[0] if len(rest) == 1 else {"anyOf": rest}
        return {k: _without_null(v) for k, v in node.items() if k != "default"
                or v is not None}
    if isinstance(node, list):
        return [_without_null(v) for v in node]
    return node


def schema(name: str) -> dict:
    """The JSON Schema ``name`` (one of :data:`SCHEMA_NAMES`) as the models give it."""
    if name == "trajectory.schema.json":
        from .document import Document

        body = Document.model_json_schema(mode="validation")
        body["title"] = "aou-trajectory/1 document"
    elif name == "robot.schema.json":
        from ..robot.toml_model import DescriptionFile

        body = _without_null(DescriptionFile.model_json_schema(mode="validation",
                                                                by_alias=True))
    else:
        raise KeyError(name)
    return {"$schema": _DIALECT, **body}


def schema_text(name: str) -> str:
    """The file ``name`` as it ships: the schema, indented, keys in the models' order."""
    return json.dumps(schema(name), indent=2) + "\n"


def shipped_text(name: str) -> str:
    """The shipped file ``name`` (inside the installed package)."""
    return (resources.files("aou_dsl") / "schemas" / name).read_text(encoding="utf-8")
