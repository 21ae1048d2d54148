"""Generate the table of docs/errors.md: every bad-input class we tried and the message it gets.

    python docs/errors_table.py           # rewrite the table in docs/errors.md
    python docs/errors_table.py --check   # exit 1 if the page differs from what the code prints

Each case runs the real call; the message in the table is the exception's text (or the one line
the command line prints). Temporary paths are shown as ``<dir>``.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

from cogmap import inference
from cogmap.cli import main
from cogmap.envs.layout_file import LayoutFileError, load_layout
from cogmap.genmodel import Factor, Modality, ModelSpec, SpecError, compile
from cogmap.genmodel.io import load, save, write_files
from cogmap.inference import InferenceError
from cogmap.inference.reduction import reduce_dirichlet

PAGE = Path(__file__).resolve().parent / "errors.md"
BEGIN, END = "<!-- TABLE -->", "<!-- END TABLE -->"


def _spec(**kw) -> ModelSpec:
    d = dict(factors=[Factor("s", 2, 2)], modalities=[Modality("o", 2, ("s",))],
             A={"o": np.eye(2)}, B={"s": np.stack([np.eye(2), np.eye(2)[::-1]], -1)})
    d.update(kw)
    return ModelSpec(**d)


def _model():
    return compile(_spec(pA={"o": np.eye(2) + 1.0}, pB={"s": np.ones((2, 2, 2))},
                         A={"o": (np.eye(2) + 1.0) / 3}, B={"s": np.full((2, 2, 2), 0.5)}))


def _compile(**kw):
    return lambda d: compile(_spec(**kw))


def _infer(name="exact", actions=((1,),), **kw):
    def run(d):
        m = _model()
        return inference.get(name)(m, [m.live_D(0)], [0, 1] if actions else [0], list(actions) if actions else None,
                                   **kw)
    return run


def _forge(arrays_edit=None, meta_edit=None, edit_json_only=None):
    def run(d):
        npz, js = save(_model(), Path(d) / "model")
        meta = json.loads(js.read_text())
        with np.load(npz) as z:
            arrays = {k: z[k].copy() for k in z.files}
        if arrays_edit:
            arrays_edit(arrays)
        if meta_edit:
            meta_edit(meta)
        write_files(npz, js, arrays, meta)
        if edit_json_only:
            meta = json.loads(js.read_text())
            edit_json_only(meta)
            js.write_text(json.dumps(meta))
        return load(Path(d) / "model")
    return run


def _set(name, index, value):
    def edit(arrays):
        arrays[name][index] = value
    return edit


def _replace_npz(make):
    def run(d):
        npz, _ = save(_model(), Path(d) / "model")
        npz.unlink()
        make(npz)
        return load(Path(d) / "model")
    return run


def _cli(*argv):
    return lambda d: main([a.replace("<dir>", d) for a in argv])


def _reduce(d):
    red = reduce_dirichlet(np.array([4.0, 1.0, 2.0]), np.ones(3), np.array([1.0, 1.0, 0.0]))
    return f"F = {red.free_energy}, accept = {red.accept}"


#: (where, bad input, call); the call raises, or for the CLI prints one line and returns 2
CASES = [
    ("spec", "a modality depends on the same factor twice",
     _compile(modalities=[Modality("o", 2, ("s", "s"))], A={"o": np.full((2, 2, 2), 0.5)})),
    ("spec", "no factors", _compile(factors=[], modalities=[], A={}, B={})),
    ("spec", "no modalities", _compile(modalities=[], A={})),
    ("spec", "NaN preference", _compile(C={"o": [np.nan, 0.0]})),
    ("spec", "infinite preference", _compile(C={"o": [np.inf, 0.0]})),
    ("spec", "complex likelihood", _compile(A={"o": np.eye(2) + 0j})),
    ("spec", "non-numeric preferences", _compile(C={"o": ["high", "low"]})),
    ("spec", "string factor size", _compile(factors=[Factor("s", "2", 2)])),
    ("spec", "float factor size", _compile(factors=[Factor("s", 2.0, 2)])),
    ("spec", "float modality size", _compile(modalities=[Modality("o", 2.0, ("s",))])),
    ("spec", "A given as a list, not a dict", _compile(A=[np.eye(2)])),
    ("spec", "A as a ragged nested list", _compile(A={"o": [[1, 0], [0]]})),
    ("spec", "A as a nested list of the wrong shape", _compile(A={"o": [[0.5, 0.5]]})),
    ("spec", "A with a negative entry", _compile(A={"o": [[1.5, 0.0], [-0.5, 1.0]]})),
    ("spec", "A column not normalised", _compile(A={"o": [[0.5, 0.0], [0.4, 1.0]]})),
    ("spec", "unknown factor in depends_on", _compile(modalities=[Modality("o", 2, ("place",))])),
    ("spec", "capacity far beyond reason (dense B)",
     _compile(factors=[Factor("s", 2, 2, growable=True, capacity=10**6)])),
    ("inference", "float action", _infer(actions=((1.0,),))),
    ("inference", "string action", _infer(actions=("1",))),
    ("inference", "bool action", _infer(actions=(True,))),
    ("inference", "action out of range", _infer(actions=(5,))),
    ("inference", "num_iter=0", _infer("fpi", actions=(), num_iter=0)),
    ("inference", "num_iter negative", _infer("vmp", actions=(), num_iter=-2)),
    ("inference", "complex prior", lambda d: inference.get("exact")(_model(), [np.array([0.5, 0.5]) + 0j], [0])),
    ("inference", "prior not normalised", lambda d: inference.get("exact")(_model(), [np.array([0.5, 0.6])], [0])),
    ("inference", "observation index out of range", lambda d: inference.get("exact")(_model(), [_model().live_D(0)],
                                                                                     [7])),
    ("load", "description edited by hand", _forge(edit_json_only=lambda m: m.update(prior_count=5.0))),
    ("load", "npz truncated", lambda d: (lambda p: (p.write_bytes(p.read_bytes()[:100]), load(p))[1])(
        save(_model(), Path(d) / "model")[0])),
    ("load", "negative prior count", _forge(_set("pB0", (0, 0, 0), -1.0))),
    ("load", "NaN prior count", _forge(_set("pA0", (0, 0), np.nan))),
    ("load", "negative likelihood entry", _forge(_set("A0", (0, 0), -0.5))),
    ("load", "D not normalised", _forge(_set("D0", 0, 0.9))),
    ("load", "factor renamed in the description", _forge(meta_edit=lambda m: m["factors"][0].update(name="x"))),
    ("load", "huge capacity in the description", _forge(meta_edit=lambda m: m.update(capacities=[10**6]))),
    ("load", "string size in the description", _forge(meta_edit=lambda m: m.update(num_obs=["2"]))),
    ("load", "a directory in place of model.npz", _replace_npz(lambda p: p.mkdir())),
    ("load", "a link to a device in place of model.npz", _replace_npz(lambda p: os.symlink("/dev/zero", p))),
    ("load", "file missing", lambda d: load(Path(d) / "absent")),
    ("reduction", "zero reduced prior where data was observed (not an error: rejected)", _reduce),
    ("cli", "cogmap explore --steps 0", _cli("explore", "--steps", "0")),
    ("cli", "cogmap explore --steps -1", _cli("explore", "--steps", "-1")),
    ("cli", "cogmap explore --patience -5", _cli("explore", "--patience", "-5")),
    ("cli", "cogmap compare-inference --steps 0", _cli("compare-inference", "--steps", "0")),
    ("cli", "cogmap reproduce exploration --workers 0", _cli("reproduce", "exploration", "--workers", "0")),
    ("cli", "cogmap compare-inference --model MISSING.npz", _cli("compare-inference", "--model", "<dir>/m.npz")),
    ("cli", "cogmap goal --run MISSING_DIR", _cli("goal", "--run", "<dir>/run", "--goal-obs", "0")),
    ("cli", "cogmap explore --out NON_EMPTY_DIR (neither --resume nor --force)",
     lambda d: (Path(d, "old.txt").write_text("x"), main(["explore", "--out", d, "--quiet"]))[1]),
    ("cli", "cogmap explore --resume --force", _cli("explore", "--out", "<dir>", "--resume", "--force")),
    ("cli", "cogmap explore --resume on an empty directory", _cli("explore", "--out", "<dir>", "--resume")),
    ("cli", "cogmap goal --resume (not supported)", _cli("goal", "--run", "<dir>", "--goal-obs", "0", "--resume")),
    ("cli", "cogmap explore --time-limit -1", _cli("explore", "--time-limit", "-1")),
]


def _building(edit=None, name="b.json"):
    """Load a small valid building (docs/examples style) after ``edit``; the file lives in <dir>."""
    def run(d):
        b = {"name": "room", "walls": [{"from": [0, 0], "to": [6, 0]}, {"from": [6, 0], "to": [6, 4]},
                                       {"from": [6, 4], "to": [0, 4]}, {"from": [0, 4], "to": [0, 0]},
                                       {"from": [3, 0], "to": [3, 4], "gaps": [[1.0, 2.6]]}],
             "furniture": [{"type": "box", "x": 1.0, "y": 3.3, "size": [1.0, 0.6]}],
             "starts": [[1.0, 1.0, 0.0], [5.0, 2.0, 3.14]]}
        if edit:
            edit(b)
        path = Path(d) / name
        path.write_text(json.dumps(b))
        return load_layout(path)
    return run


def _set_in(path, value):
    def edit(b):
        node = b
        for k in path[:-1]:
            node = node[k]
        if value is KeyError:
            del node[path[-1]]
        else:
            node[path[-1]] = value
    return edit


def _huge_png(d):
    p = Path(d) / "huge.png"
    p.write_bytes(b"\x89PNG\r\n\x1a\n" + b"\x00\x00\x00\x0dIHDR" + (100000).to_bytes(4, "big") * 2 + b"\x08" + bytes(4))
    return load_layout(p)


CASES += [
    ("layout file", "missing key", _building(_set_in(["walls", 1, "to"], KeyError))),
    ("layout file", "unknown key (a typo)", _building(_set_in(["furniture", 0, "colour"], [1, 0, 0]))),
    ("layout file", "non-numeric size", _building(_set_in(["furniture", 0, "size"], ["wide", 1]))),
    ("layout file", "negative size", _building(_set_in(["walls", 0, "thickness"], -0.1))),
    ("layout file", "wall of zero length", _building(_set_in(["walls", 2, "to"], [6, 4]))),
    ("layout file", "door gap outside its wall", _building(_set_in(["walls", 4, "gaps"], [[3.0, 5.0]]))),
    ("layout file", "start outside the bounds", _building(_set_in(["starts", 1], [7.0, 2.0, 0.0]))),
    ("layout file", "start inside an obstacle", _building(_set_in(["starts", 1], [1.0, 3.3, 0.0]))),
    ("layout file", "start where the robot does not fit", _building(_set_in(["starts", 1], [5.85, 2.0, 0.0]))),
    ("layout file", "starts that cannot reach each other", _building(_set_in(["walls", 4, "gaps"], []))),
    ("layout file", "building open to the outside", _building(_set_in(["walls", 1, "gaps"], [[1.0, 3.0]]))),
    ("layout file", "no free space", _building(lambda b: b.update(
        walls=[{"from": [0, 0], "to": [0.3, 0]}, {"from": [0.3, 0], "to": [0.3, 0.3]},
               {"from": [0.3, 0.3], "to": [0, 0.3]}, {"from": [0, 0.3], "to": [0, 0]}], furniture=[], starts=None))),
    ("layout file", "invalid JSON", lambda d: (Path(d, "b.json").write_text("{'name': 1}"),
                                               load_layout(Path(d, "b.json")))[1]),
    ("layout file", "a directory in place of the file", lambda d: (Path(d, "b.json").mkdir(),
                                                                   load_layout(Path(d, "b.json")))[1]),
    ("layout file", "PNG plan of 100000 x 100000 pixels (refused from its header)", _huge_png),
    ("cli", "cogmap explore --env MISSING.json", _cli("explore", "--env", "<dir>/missing.json", "--out", "<dir>/run")),
    ("cli", "cogmap explore --env building:V:1 (unknown procedural kind)",
     _cli("explore", "--env", "building:V:1", "--out", "<dir>/run")),
]


def _without_ray(d):
    saved = sys.modules.get("ray", False)
    sys.modules["ray"] = None  # as if Ray were not installed
    try:
        return main(["reproduce", "exploration", "--executor", "ray", "--out", d, "--quiet"])
    finally:
        if saved is False:
            del sys.modules["ray"]
        else:
            sys.modules["ray"] = saved


CASES.append(("cli", "cogmap reproduce ... --executor ray, without Ray installed", _without_ray))


def message(call) -> str:
    """The message ``call`` ends with (exception text, or the CLI's one stderr line)."""
    with tempfile.TemporaryDirectory() as d:
        err = io.StringIO()
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                result = call(d)
        except (SpecError, InferenceError, LayoutFileError) as exc:
            text = str(exc)
        except SystemExit as stop:
            if stop.code != 2:
                raise
            text = err.getvalue().strip()
        else:
            text = err.getvalue().strip() if not isinstance(result, str) else result
        return " ".join(text.replace(os.path.realpath(d), "<dir>").replace(d, "<dir>").split())


def table() -> str:
    rows = ["| where | bad input | message |", "|---|---|---|"]
    for where, what, call in CASES:
        rows.append(f"| {where} | {what} | `{message(call).replace('|', '/')}` |")
    return "\n".join(rows)


def page_table() -> str:
    text = PAGE.read_text()
    return text[text.index(BEGIN) + len(BEGIN): text.index(END)].strip()


def main_(argv: list[str]) -> int:
    new = table()
    if "--check" in argv:
        return 0 if new == page_table() else 1
    text = PAGE.read_text()
    PAGE.write_text(text[: text.index(BEGIN) + len(BEGIN)] + "\n" + new + "\n" + text[text.index(END):])
    return 0


if __name__ == "__main__":
    sys.exit(main_(sys.argv[1:]))
