"""``aouc study build``: a study file made into a static jsPsych experiment.

The folder written (the *site*) is what participants load, and nothing in it says which
stimulus is which:

- ``index.html`` loads jsPsych (a pinned CDN version with integrity hashes, or the
  study's own copy: :mod:`aou_dsl.study.jspsych`) and ``experiment.js`` (aou's, the same
  for every study);
- ``timeline.json`` holds the texts, the options and, per question, only its blind id
  and the videos it shows (Part B: the pair's base state, named by the question as the
  paper's was, its two videos in the order of their names, and an opaque number whose
  parity says which is the low variant);
- ``stimuli/<sha256>.mp4``: each video named by the hash of its own bytes.

The researcher's record is written beside the site, never inside it: ``SITE.manifest.json``
names every stimulus with its blind id, the behaviour it came from, the sha256 of the
``.aou`` text compiled (a Part B variant's own text), of the file on disk and of the
robot's description, and of the video. ``--jatos`` writes ``SITE.jzip`` beside it too.

Rendering reuses ``aouc render``'s code (one video per stimulus, no caption) and Part B's
variants are ``aouc variants``'s. A video is keyed by the sha256 of everything it depends
on (aou's version, the text compiled, the robot's name and file contents, width, height
and frame rate); a text not seen before is compiled, and keyed again by its motion (the
samples, joints and goal), so that texts differing only where the motion does not (a
comment, a variant whose value is its base's) share one video. ``SITE/.aou-cache.json``
maps both keys to videos, and a video whose key is there and whose file still has its
hash is not drawn again. Videos are drawn ``jobs`` at a time, each in a process of its
own, with progress on standard error.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import sys
import time
import uuid
import zipfile
from importlib import resources

from ..core.codes import E702, I502, I506
from ..core.diagnostics import AouError, Span, diag
from ..core.files import guard_output, is_own_output, write_atomic
from .spec import Study
from .stimuli import (
    CACHE,
    GENERATOR,
    WORK,
    Stim,
    file_sha,
    jatos_path,
    load_cache,
    manifest_path,
    motion_key,
    plan_stimuli,
    render_one,
    render_settings,
    robot_file,
    sha256_hex,
    video_key,
)

__all__ = ["GENERATOR", "Stim", "build_study", "manifest_path", "plan_stimuli", "write_jzip"]

def _guard_site(site: str, reads: list[str]) -> None:
    """A site goes into a new or empty folder, or over one this command built."""
    where = Span.whole_file(site)
    if os.path.lexists(site) and not os.path.isdir(site):
        raise AouError(diag(I502, f"cannot build into `{site}`: it is a file", where))
    real = os.path.realpath(site)
    for read in reads:
        if os.path.realpath(read).startswith(real + os.sep):
            raise AouError(diag(I502, f"refusing to build into `{site}`: it holds `{read}`, "
                                "which this command reads", where, input=read))
    own = {"stimuli", CACHE, WORK, "timeline.json", "index.html", "experiment.js", "jspsych"}
    if os.path.isdir(site) and not is_own_output(os.path.join(site, "timeline.json")) and \
            set(os.listdir(site)) - own:  # (a build stopped early left only its own files)
        raise AouError(diag(I502, f"refusing to build into `{site}`: the folder holds files "
                            "other than a study aou built", where,
                            hint="build into a new or empty folder"))


def _own_jzip(path: str) -> bool:
    try:
        with zipfile.ZipFile(path) as z:
            doc = json.loads(z.read("study.jas"))
        return str(doc["data"]["comments"]).startswith("written by aouc")
    except (OSError, KeyError, ValueError, TypeError, zipfile.BadZipFile):
        return False


def build_study(study: Study, site: str, *, jobs: int = 1, jspsych: str | None = None,
                jatos: bool = False, log=None) -> dict:
    """Build ``study`` into the folder ``site``; what was done (videos drawn and reused,
    files written)."""
    log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
    robot, robot_path = robot_file(study)
    reads = [study.path, *(s.path for s in study.part_a), *(p.path for p in study.pairs)]
    _guard_site(site, reads)
    guard_output(manifest_path(site), reads, force=False)
    if jatos and os.path.exists(jatos_path(site)) and not _own_jzip(jatos_path(site)):
        raise AouError(diag(I506, f"refusing to replace `{jatos_path(site)}`: aou did not "
                            "write it", Span.whole_file(jatos_path(site))))
    try:
        with open(robot_path, "rb") as fh:
            robot_sha = sha256_hex(fh.read())
    except OSError as exc:
        raise AouError(diag(E702, f"the robot's file `{robot_path}` cannot be read "
                            f"({exc.strerror})", Span.whole_file(study.path))) from None
    stims = plan_stimuli(study)
    render = render_settings(study)
    keys = [video_key(s, robot, robot_sha, render) for s in stims]
    stimuli = os.path.join(site, "stimuli")
    os.makedirs(stimuli, exist_ok=True)
    cache, by_motion = load_cache(site), load_cache(site, "motions")
    videos: dict[str, str] = {}  # text key -> video sha
    motions: dict[str, str] = {}  # motion key -> video sha

    def ok(sha: str | None) -> bool:  # a cached video counts only while it has its hash
        return bool(sha) and file_sha(os.path.join(stimuli, f"{sha}.mp4")) == sha

    for key in set(keys):
        if ok(cache.get(key)):
            videos[key] = cache[key]
    # A text not seen before is compiled: a motion already drawn is not drawn again.
    todo: dict[str, Stim] = {}  # motion key -> the stimulus to draw
    waiting: dict[str, list[str]] = {}  # motion key -> text keys showing it
    for s, key in zip(stims, keys, strict=True):
        if key in videos or any(key in ks for ks in waiting.values()):
            continue
        mkey = motion_key(s, robot, robot_sha, render)
        if ok(by_motion.get(mkey)):
            videos[key] = motions[mkey] = by_motion[mkey]
            continue
        todo.setdefault(mkey, s)
        waiting.setdefault(mkey, []).append(key)
    log(f"study build: {len(stims)} videos, {len(stims) - sum(1 for k in keys if k not in videos)}"
        f" up to date, {len(todo)} to draw ({jobs} at a time)")

    def keep(mkey: str, sha: str) -> None:  # the cache is written as each video is drawn
        motions[mkey] = sha
        for key in waiting[mkey]:
            videos[key] = sha
        _save_cache(site, videos, motions, reads)

    drawn = _draw_all(todo, site, robot, render, jobs, log, keep)
    jspsych_files = []
    if jspsych:
        from .jspsych import copy_local

        jspsych_files = copy_local(jspsych, site)
    elif os.path.isdir(os.path.join(site, "jspsych")):
        shutil.rmtree(os.path.join(site, "jspsych"))  # a rebuild for the CDN drops it
    video_of = {(s.item, s.role): f"stimuli/{videos[k]}.mp4"
                for s, k in zip(stims, keys, strict=True)}
    timeline = timeline_doc(study, video_of)
    write_atomic(os.path.join(site, "timeline.json"),
                 (json.dumps(timeline, indent=1) + "\n").encode(), inputs=reads)
    script = resources.files("aou_dsl.study").joinpath("static/experiment.js").read_bytes()
    write_atomic(os.path.join(site, "experiment.js"), script, inputs=reads)
    write_atomic(os.path.join(site, "index.html"),
                 index_html(study.title, local=bool(jspsych)).encode(), inputs=reads)
    used = set(videos[k] for k in keys)
    for name in os.listdir(stimuli):  # videos of an earlier build no stimulus shows
        stem, ext = os.path.splitext(name)
        if ext == ".mp4" and len(stem) == 64 and stem not in used:
            os.remove(os.path.join(stimuli, name))
    man = manifest(study, stims, keys, videos, robot, robot_path, robot_sha, render,
                   bool(jspsych))
    write_atomic(manifest_path(site), (json.dumps(man, indent=1) + "\n").encode(),
                 inputs=reads)
    used_shas = {videos[k] for k in keys}
    _save_cache(site, {k: videos[k] for k in set(keys)},
                {m: v for m, v in {**by_motion, **motions}.items() if v in used_shas}, reads)
    if jatos:
        write_jzip(study, site, jspsych_files)
    distinct = len({videos[k] for k in keys})
    return {"videos": distinct, "drawn": len(drawn), "reused": distinct - len(drawn)}


def _save_cache(site: str, videos: dict[str, str], motions: dict[str, str],
                reads: list[str]) -> None:
    write_atomic(os.path.join(site, CACHE), (json.dumps(
        {"generator": GENERATOR, "videos": dict(sorted(videos.items())),
         "motions": dict(sorted(motions.items()))}, indent=1) + "\n").encode(), inputs=reads)


def _draw_all(todo: dict[str, Stim], site: str, robot: str, render: dict, jobs: int,
              log, keep) -> dict[str, str]:
    """Draw each video of ``todo`` (key -> stimulus), ``jobs`` at once; key -> sha."""
    if not todo:
        return {}
    work = os.path.join(site, WORK)
    os.makedirs(work, exist_ok=True)
    out: dict[str, str] = {}
    t0 = time.perf_counter()

    def done(key: str, errors: list[str]) -> None:
        s = todo[key]
        if errors:
            raise AouError(diag(E702, f"{s.label} ({os.path.basename(s.path)}"
                                f"{f', {s.descriptor}={s.value:g}' if s.descriptor else ''}) "
                                f"cannot be rendered: {errors[0]}", Span.whole_file(s.path)))
        tmp = os.path.join(work, f"{key}.mp4")
        sha = file_sha(tmp)
        assert sha is not None
        os.replace(tmp, os.path.join(site, "stimuli", f"{sha}.mp4"))
        out[key] = sha
        keep(key, sha)
        log(f"study build: [{len(out)}/{len(todo)}] drew {s.label} "
            f"({os.path.basename(s.path)}) at {time.perf_counter() - t0:.1f} s")

    try:
        if jobs <= 1 or len(todo) == 1:
            for key, s in todo.items():
                done(key, render_one(s.text, s.path, robot,
                                      os.path.join(work, f"{key}.mp4"), render))
        else:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor, as_completed

            with ProcessPoolExecutor(min(jobs, len(todo)),
                                     mp_context=multiprocessing.get_context("spawn")) as pool:
                futs = {pool.submit(render_one, s.text, s.path, robot,
                                    os.path.join(work, f"{key}.mp4"), render): key
                        for key, s in todo.items()}
                try:
                    for f in as_completed(futs):
                        done(futs[f], f.result())
                except BaseException:
                    pool.shutdown(wait=False, cancel_futures=True)
                    raise
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return out


def timeline_doc(study: Study, video_of: dict[tuple[str, str], str]) -> dict:
    """What the page needs, blinded: blind ids, videos, texts and options only."""
    pairs = []
    for p in study.pairs:
        low, high = video_of[(p.id, "low")], video_of[(p.id, "high")]
        first_low = low <= high
        rng = random.Random(f"{study.seed}:{p.id}:{low}:{high}")
        k = rng.randrange(1, 2**30) * 2 + (0 if first_low else 1)
        pairs.append({"item": p.id, "state": p.state, "videos": sorted([low, high]), "k": k})
    attention = [{"item": f"C{i}", "question": c["question"], "options": list(c["options"]),
                  "answer": c["answer"]} for i, c in enumerate(study.attention, 1)]
    return {
        "generator": GENERATOR,
        "title": study.title,
        "seed": study.seed,
        "texts": {k: study.texts.get(k, "") for k in
                  ("consent", "instructions_a", "instructions_b", "end")},
        "demographics": list(study.demographics),
        "states": list(study.states), "others": study.others, "none": study.none,
        "intensity": study.intensity,
        "part_a": [{"item": s.id, "video": video_of[(s.id, "A")]} for s in study.part_a],
        "part_b": pairs,
        "attention": attention,
        "completion": dict(study.completion),
    }


def index_html(title: str, *, local: bool, jatos: bool = False) -> str:
    import html

    from .jspsych import urls

    css, *scripts = urls(local)
    cross = "" if local else ' crossorigin="anonymous"'
    tags = [f'<link rel="stylesheet" href="{css[0]}" integrity="{css[1]}"{cross}>']
    if jatos:
        tags.append('<script src="jatos.js"></script>')
    tags += [f'<script src="{u}" integrity="{h}"{cross}></script>' for u, h in scripts]
    tags.append('<script src="experiment.js"></script>')
    head = "\n".join(f"  {t}" for t in tags)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
  <meta charset="utf-8">
  <meta name="viewport" content="width=device-width, initial-scale=1">
  <meta name="referrer" content="no-referrer">
  <title>{html.escape(title)}</title>
{head}
  <style>
    .aou-videos {{ display: flex; flex-wrap: wrap; gap: 12px; justify-content: center; }}
    .aou-videos figure {{ margin: 0; padding: 4px; border: 3px solid transparent; }}
    .aou-videos figure.aou-asked {{ border-color: #1565c0; }}
    .aou-videos video {{ max-width: 100%; width: 320px; background: #000; }}
    .aou-form {{ text-align: left; max-width: 640px; margin: 0 auto; }}
    .aou-form label {{ display: block; margin: 4px 0; }}
    .aou-form textarea {{ width: 100%; }}
  </style>
</head>
<body>
  <noscript>This study needs JavaScript.</noscript>
</body>
</html>
"""


def manifest(study: Study, stims: list[Stim], keys: list[str], videos: dict[str, str],
             robot: str, robot_path: str, robot_sha: str, render: dict, local: bool) -> dict:
    from ..version import __version__
    from .jspsych import PACKAGES

    base = os.path.dirname(os.path.abspath(study.path))
    with open(study.path, "rb") as fh:
        study_sha = sha256_hex(fh.read())
    entries = []
    for s, k in zip(stims, keys, strict=True):
        entries.append({
            "item": s.item, "role": s.role,
            "behaviour": os.path.relpath(os.path.abspath(s.path), base),
            "behaviour_sha256": file_sha(s.path),
            "aou_sha256": sha256_hex(s.text.encode()),
            "state": s.state, "descriptor": s.descriptor, "value": s.value,
            "video": f"stimuli/{videos[k]}.mp4", "video_sha256": videos[k], "key": k})
    return {
        "generator": f"{GENERATOR} {__version__}",
        "study": os.path.abspath(study.path), "study_sha256": study_sha,
        "robot": os.path.basename(robot), "robot_file": robot_path,
        "robot_sha256": robot_sha, "render": render,
        "jspsych": {"source": "local" if local else "cdn", "packages": PACKAGES},
        "stimuli": entries,
    }


def write_jzip(study: Study, site: str, jspsych_files: list[str]) -> str:
    """A JATOS study archive of the site: ``study.jas`` (the study's properties, JATOS's
    version 3) and the site's files in a folder of their own, ``index.html`` loading
    ``jatos.js`` so that answers go to JATOS. Written beside the site."""
    from ..core.files import atomic

    name = os.path.basename(os.path.normpath(site)) or "study"
    ns = uuid.UUID("6f1c8b1e-4d1a-4b7e-9a55-0a0c5e5d2a11")
    study_uuid = str(uuid.uuid5(ns, f"{study.title}:{study.seed}"))
    jas = {"version": "3", "data": {
        "uuid": study_uuid, "title": study.title, "description": "",
        "groupStudy": False, "linearStudy": True, "allowPreview": False,
        "dirName": name, "comments": f"written by {GENERATOR}", "jsonData": None,
        "endRedirectUrl": study.completion.get("redirect", ""), "studyEntryMsg": None,
        "componentList": [{"uuid": str(uuid.uuid5(ns, study_uuid + ":1")),
                           "title": study.title, "htmlFilePath": "index.html",
                           "reloadable": False, "active": True, "comments": "",
                           "jsonData": None}],
        "batchList": []}}
    path = jatos_path(site)
    files = ["timeline.json", "experiment.js"]
    files += sorted(f"stimuli/{n}" for n in os.listdir(os.path.join(site, "stimuli")))
    files += sorted(os.path.relpath(f, site).replace(os.sep, "/") for f in jspsych_files)
    with atomic(path) as tmp, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("study.jas", json.dumps(jas, indent=1))
        z.writestr(f"{name}/index.html",
                   index_html(study.title, local=bool(jspsych_files), jatos=True))
        for f in files:
            z.write(os.path.join(site, f), f"{name}/{f}")
    return path
