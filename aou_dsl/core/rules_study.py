"""The rules of perception studies (``aouc study``): the study file, the behaviours it
shows, the answers it collects and a simulation's policy. Kept apart from :mod:`.rules`
(which lists them among its codes) to keep that table's module small."""

from __future__ import annotations

from .codes import E701, E702, E703, E704
from .rule_model import Rule, Severity

__all__ = ["STUDY_RULES"]

_E = Severity.ERROR

STUDY_RULES = [
    Rule(E701, "bad-study-file", _E,
         "A study file (`study.toml`) is not one aou can run: a key it does not know, a "
         "value of the wrong type or out of range, a required table missing. The message "
         "names the key.",
         "A study built from a misread file would show participants something the "
         "researcher did not design.",
         "[part_b]\npairs = [{behaviour = 'c.aou', descriptor = 'speed', low = 1, high = 2}]"),
    Rule(E702, "bad-stimulus", _E,
         "A behaviour a study shows cannot be used: it is missing, it has errors, or a "
         "Part B pair's variant does not say what the pair is about.",
         "Every answer must trace back to the motion it was given for.",
         "[part_a]\nbehaviours = ['missing.aou']"),
    Rule(E703, "bad-results", _E,
         "A results file does not read as study answers: not JSON, CSV or SQLite of the "
         "forms docs/study.md gives, an answer to a question the study does not have, or "
         "a value out of the question's options.",
         "An analysis of misread answers reports effects no participant produced.",
         "aouc study analyze notes.txt --study study.toml -o report"),
    Rule(E704, "bad-policy", _E,
         "A simulated participants' policy file gives probabilities that are not numbers "
         "in [0, 1] summing to 1, or names a question or an option the study lacks.",
         "A simulation is only as good as the policy it follows.",
         "[part_a.confident]\nconfident = 0.8\ncurious = 0.5"),
]
