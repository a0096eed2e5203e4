"""Write the JSON Schema files that ship with aou (``aou_dsl/schemas/``) from the pydantic
models. Run after changing a model: ``python tools/write_schemas.py``."""

from __future__ import annotations

import pathlib

from aou_dsl.core.files import write_atomic
from aou_dsl.measuring.schema_files import SCHEMA_NAMES, schema_text

FOLDER = pathlib.Path(__file__).resolve().parent.parent / "aou_dsl" / "schemas"


def main() -> None:
    for name in SCHEMA_NAMES:
        write_atomic(str(FOLDER / name), schema_text(name).encode())
        print(FOLDER / name)


if __name__ == "__main__":
    main()
