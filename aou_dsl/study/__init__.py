"""Perception studies of behaviours: the study file (``spec``), the web experiment built
from it (``build``, ``jspsych``) and its server (``serve``), simulated participants
(``simulate``), the answers (``answers``) and their analysis (``stats``, ``analyze``,
``report_files``). The command line is ``aouc study``; docs/study.md walks through it."""
