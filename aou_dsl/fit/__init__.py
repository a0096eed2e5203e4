"""Fitting a behaviour to an arm, and the hints that say how: one module per concern.

:mod:`~aou_dsl.fit.rounding` (values written with so many significant digits),
:mod:`~aou_dsl.fit.quantity` (a number with its unit, in a statement's text),
:mod:`~aou_dsl.fit.text_edits` (a value of a statement changed in the file's text),
:mod:`~aou_dsl.fit.refusals` (what the compiler refused, typed, as the fit reads it),
:mod:`~aou_dsl.fit.search` (the largest value that fits),
:mod:`~aou_dsl.fit.plan` (which values to change, and by how much),
:mod:`~aou_dsl.fit.reach` (a pose brought within reach),
:mod:`~aou_dsl.fit.amplitude` (a shiver narrowed to what the wrist follows),
:mod:`~aou_dsl.fit.rounds` (``--fit``: build, change, build again),
:mod:`~aou_dsl.fit.every_change` (a refusal's hint with every change the file needs) and
:mod:`~aou_dsl.fit.guard` (no text or edit offered that the language refuses).

It sits in the compiler's layer: the compiler reads its rounding, search, refusals and
edits to word its hints, and the reach and amplitude fits follow the compiler's own path.
"""
