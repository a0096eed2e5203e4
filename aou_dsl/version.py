"""The version of aou, in one place (the package and every file it writes)."""

__version__ = "0.2.0"
