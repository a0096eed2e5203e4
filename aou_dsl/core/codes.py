"""Every diagnostic code as a constant, so a misspelt code fails when its module is
imported. Made from the registry (:data:`aou_dsl.core.rules.RULES`); a test keeps the
two equal."""

from __future__ import annotations

from typing import Final

__all__ = ["C301", "C302", "C303", "C304", "C305", "C306", "C308", "C309", "C310", "C311",
           "C312", "C313", "I501", "I502", "I503", "I504", "I505", "I506", "M201", "M202",
           "M203", "M204", "R401", "R402", "R403", "R404", "R405", "R406", "R407", "S001",
           "S002", "S003", "V101", "V102", "V103", "V104", "V105", "V106", "V107", "V108",
           "V109", "V110", "V111", "V112", "V113", "V114", "V115", "V116", "V117", "V118",
           "V119", "V120", "V121", "V122", "V123", "V124", "V125", "V126"]

C301: Final = "C301"
C302: Final = "C302"
C303: Final = "C303"
C304: Final = "C304"
C305: Final = "C305"
C306: Final = "C306"
C308: Final = "C308"
C309: Final = "C309"
C310: Final = "C310"
C311: Final = "C311"
C312: Final = "C312"
C313: Final = "C313"
I501: Final = "I501"
I502: Final = "I502"
I503: Final = "I503"
I504: Final = "I504"
I505: Final = "I505"
I506: Final = "I506"
M201: Final = "M201"
M202: Final = "M202"
M203: Final = "M203"
M204: Final = "M204"
R401: Final = "R401"
R402: Final = "R402"
R403: Final = "R403"
R404: Final = "R404"
R405: Final = "R405"
R406: Final = "R406"
R407: Final = "R407"
S001: Final = "S001"
S002: Final = "S002"
S003: Final = "S003"
V101: Final = "V101"
V102: Final = "V102"
V103: Final = "V103"
V104: Final = "V104"
V105: Final = "V105"
V106: Final = "V106"
V107: Final = "V107"
V108: Final = "V108"
V109: Final = "V109"
V110: Final = "V110"
V111: Final = "V111"
V112: Final = "V112"
V113: Final = "V113"
V114: Final = "V114"
V115: Final = "V115"
V116: Final = "V116"
V117: Final = "V117"
V118: Final = "V118"
V119: Final = "V119"
V120: Final = "V120"
V121: Final = "V121"
V122: Final = "V122"
V123: Final = "V123"
V124: Final = "V124"
V125: Final = "V125"
V126: Final = "V126"
