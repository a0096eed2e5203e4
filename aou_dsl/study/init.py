"""``aouc study init DIR``: a study file that reproduces the paper's design.

Part A shows the four base behaviours of the study (their descriptors are those of the
paper's Table II: docs/model.md); Part B varies each along the descriptors the paper
varied (20 pairs). The paper does not give the variants' values; the ones written here
are aou's, each pair's base value at one end, so a researcher reads and edits them.
"""

from __future__ import annotations

import os
import tomllib
from importlib import resources

from ..core.files import write_atomic

__all__ = ["BASES", "PAIRS", "PART_B_BASES", "init_study", "written_names"]

#: The four base behaviours, as the study's files say them.
BASES = {
    "confident": ("A single uninterrupted approach, then a hold at the pre-grasp pose.",
                  "approach a=0.1\npause 1.67s\n"),
    "curious": ("Approaches while looking at the goal from the left and from the right.",
                "approach a=0.09\npause 1.25s x3\ngaze horizontal 20deg x2\n"),
    "hesitant": ("Advance, freeze, withdraw partly, freeze, repeat.",
                 "approach a=0.05\npause 1.67s x5\nretreat 0.06m a=0.12 x3\n"),
    "fearful": ("A rapid withdrawal punctuated by freezes and a tremor.",
                "approach a=0.1\npause 1.25s x4\nretreat 0.06m a=2\nshiver 6deg for 1.25s\n"),
}
#: The paper's design (``static/paper.toml``): its twenty variations (base, descriptor,
#: low, high) with aou's values, and the bases that add the statement a pair varies.
_PAPER = tomllib.loads(resources.files(__package__).joinpath("static", "paper.toml")
                       .read_text(encoding="utf-8"))
PAIRS = [(b, d, lo, hi) for b, d, lo, hi in _PAPER["pairs"]]
#: (base, descriptor) -> (file, statement): the paper varied a tilt and a vertical gaze
#: that its base stimuli did not have. A variant changes one value of a statement the
#: file holds, so these pairs vary a base with that statement added, written beside it.
PART_B_BASES = {(b, d): (f, st) for b, d, f, st in _PAPER["added"]}


def _pair_file(base: str, descriptor: str) -> str:
    return PART_B_BASES.get((base, descriptor), (base, ""))[0]


def written_names() -> list[str]:
    """The files ``init_study`` writes, relative to its folder."""
    stems = list(BASES) + sorted({f for f, _ in PART_B_BASES.values()})
    return ["study.toml", *(f"behaviours/{n}.aou" for n in stems)]


STUDY = '''# study.toml: written by `aouc study init`; a perception study (docs/study.md).
# It reproduces the design of the study behind aou: Part A shows the four base behaviours
# together and asks which state each shows; Part B shows each beside a variant differing
# in one descriptor and asks which shows the state more.

[study]
title = "How does the robot move?"
robot = "panda"        # the arm every stimulus is compiled for
seed = 1               # orders and sides: each participant's come from it and their id

[render]
width = 640
height = 480
fps = 30

[texts]
consent = """This study is about how people read a robot arm's motion. You will watch short
videos and answer questions about them; it takes about 20 minutes. Taking part is voluntary,
and you may stop at any time. No information that identifies you is recorded."""
instructions_a = """You will see four videos of a robot arm, playing in a loop. For each,
describe in your own words how the robot behaves, choose the state that describes it best,
and rate how strongly it shows that state."""
instructions_b = """You will see pairs of videos side by side. For each pair, choose the one
that shows the named state more strongly, or say both or neither."""
demographics = ["Age", "Gender", "Ethnicity", "Education",
                "How familiar are you with robots?", "How comfortable are you around robots?"]
end = "Thank you for taking part."

[part_a]
behaviours = [{a}]
states = ["confident", "curious", "hesitant", "fearful"]
others = true          # "Others", with a text
none = true            # "None": no state
intensity = 5          # points of the intensity scale

[part_b]
pairs = [
{b}
]

# [completion]
# code = "C0DE1234"    # shown at the end (or redirect = "https://..." for a platform)
'''


def init_study(folder: str) -> list[str]:
    """Write ``folder/study.toml`` and the base behaviours it shows; the paths written."""
    written = []
    for name, (what, body) in BASES.items():
        text = (f"# {name}.aou: the study's {name} stimulus (Table II of the study, "
                f"docs/model.md).\n# {what}\nbehaviour {name} : {name}\n\n{body}")
        path = os.path.join(folder, "behaviours", f"{name}.aou")
        write_atomic(path, text.encode())
        written.append(path)
    for (name, _), (stem, statement) in sorted(PART_B_BASES.items(), key=lambda kv: kv[1]):
        path = os.path.join(folder, "behaviours", f"{stem}.aou")
        if path in written:
            continue
        what, body = BASES[name]
        text = (f"# {stem}.aou: the study's {name} stimulus with `{statement}` added, the "
                f"base of Part B's pairs\n# that vary it.\nbehaviour {stem} : {name}\n\n"
                f"{body}{statement}\n")
        write_atomic(path, text.encode())
        written.append(path)
    a = ", ".join(f'"behaviours/{n}.aou"' for n in BASES)
    b = ",\n".join(f'  {{ behaviour = "behaviours/{_pair_file(base, d)}.aou", '
                    f'descriptor = "{d}", '
                   f"low = {lo}, high = {hi} }}" for base, d, lo, hi in PAIRS)
    path = os.path.join(folder, "study.toml")
    write_atomic(path, STUDY.format(a=a, b=b).encode())
    return [path, *written]
