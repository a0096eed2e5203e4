"""The rules of primitive kinds that other packages add (the ``aou.kinds`` entry point
group, :mod:`aou_dsl.core.plugins`). Kept apart from :mod:`.rules` (which lists them
among its codes) to keep that table's module small."""

from __future__ import annotations

from .codes import K801, K802, K803
from .rule_model import Rule, Severity

__all__ = ["PLUGIN_RULES"]

PLUGIN_RULES = [
    Rule(K801, "plugin-not-loaded", Severity.WARNING,
         "An installed package offers a primitive kind (an `aou.kinds` entry point) that "
         "aou cannot use: importing it failed, or what it gives is not a kind plugin. The "
         "message names the package and why. aou goes on without it.",
         "A file that uses the kind would otherwise be refused with no word about why the "
         "installed plugin was not there.",
         "aouc rules   # with a broken plugin installed"),
    Rule(K802, "plugin-part-missing", Severity.ERROR,
         "A file uses a primitive kind from a plugin that gives nothing for the stage at "
         "hand (its measurement, its DMP part, its synthesis recipe, its studio control). "
         "The message names the kind, the plugin and the stage.",
         "Each stage must either treat the kind as its plugin defines it or say that it "
         "cannot: guessing would give a motion or a number the plugin never meant.",
         "aouc compile uses_plugin_kind.aou --format dmp   # a plugin without a DMP part"),
    Rule(K803, "plugin-kind-clash", Severity.WARNING,
         "A plugin's primitive kind has the keyword of a built-in kind or of another "
         "plugin's. The built-in (or the first plugin loaded, by package name) keeps it.",
         "One keyword must mean one motion in every file, whichever packages are installed.",
         "aouc rules   # with a plugin whose kind is named `pause`"),
]
