"""The ``editor`` part: what completion and hover say about ``anticipate`` beyond its
kind object (whose ``usage`` and ``keys`` the editor already reads)."""

from __future__ import annotations

from aou_dsl.core.units import Dim

from .descriptors import DEFINITIONS

__all__ = ["definitions", "positional"]

#: ``anticipate DIST``: the units offered after a bare number are lengths.
positional = Dim.LENGTH
#: The hover text of each of the plugin's descriptors.
definitions = DEFINITIONS
