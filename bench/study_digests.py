"""Digests of study runs, to show that a change leaves every run the same.

    python bench/study_digests.py OUT.txt             # every registered study at tiny scale,
                                                       # plus larger drone, exploration and drift runs
    python bench/study_digests.py OUT.txt drone drift  # only these studies (tiny scale)

Each line is ``study key digest``: the run key (a digest of the run's full spec) and the SHA-256
(16 hex) of its result with the timing fields removed. Run it on two commits (for example from two
checkouts) and compare the sorted files: equal lines are the same run with the same result.
"""

from __future__ import annotations

import hashlib
import json
import sys
import time

from cogmap.study.registry import execute, run_specs, studies, study_plan
from cogmap.study.runs import strip_timings

#: larger runs beside the tiny ones: (study, scale, restrictions)
LARGER = (("drone", "reduced", {"seeds": [0, 1]}),
          ("exploration", "reduced", {"envs": ["mini_warehouse"], "seeds": [0],
                                      "methods": ["aimapp", "frontier", "nbv"]}),
          ("drift", "reduced", {"seeds": [0], "methods": ["aimapp", "aimapp_revisits"]}))


def digest(result: dict) -> str:
    return hashlib.sha256(json.dumps(strip_timings(result), sort_keys=True).encode()).hexdigest()[:16]


def main(out: str, only: list[str]) -> None:
    sets = [(s, "tiny", {}) for s in (only or studies())] + ([] if only else list(LARGER))
    with open(out, "w") as fh:
        for study, scale, kw in sets:
            t0 = time.perf_counter()
            specs = run_specs(study_plan(study, scale, **kw))
            for spec in specs:
                fh.write(f"{study} {spec['key']} {digest(execute(spec)['result'])}\n")
                fh.flush()
            print(f"{study} ({scale}): {len(specs)} runs, {time.perf_counter() - t0:.1f} s", flush=True)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2:])
