"""One home for softmax, normalisation and log floors (cogmap.genmodel.numerics)."""

import re
from pathlib import Path

import numpy as np
import pytest
from scipy.special import softmax as scipy_softmax

from cogmap import genmodel
from cogmap.genmodel import numerics
from cogmap.genmodel.dirichlet import normalise_counts
from cogmap.inference import base
from cogmap.planning import efe, policies

ROOT = Path(__file__).resolve().parents[2]


def test_softmax_matches_scipy_and_does_not_overflow():
    rng = np.random.default_rng(0)
    x = rng.normal(size=7) * 5
    assert np.allclose(numerics.softmax(x), scipy_softmax(x), rtol=1e-13, atol=0)
    big = np.array([1000.0, 999.0, -1000.0])
    assert np.allclose(numerics.softmax(big), scipy_softmax(big))
    assert np.isfinite(numerics.softmax(big)).all()


def test_normalise_and_floors():
    x = np.array([[1.0, 0.0], [3.0, 0.0]])
    assert np.array_equal(numerics.normalise(x), [[0.25, 0.5], [0.75, 0.5]])  # a zero column becomes uniform
    assert np.array_equal(normalise_counts(x), numerics.normalise(x))
    assert numerics.floor_log(0.0) == pytest.approx(np.log(np.finfo(float).eps))
    assert numerics.floor_log(0.0, numerics.TINY_FLOOR) == pytest.approx(np.log(1e-300))
    q = np.array([0.0, 0.25, 0.75])
    assert numerics.xlogx(q)[0] == 0.0
    assert numerics.xlogx(q).sum() == pytest.approx(numerics.xlogx_sum(q))
    assert numerics.xlogx_sum(q) == pytest.approx(0.25 * np.log(0.25) + 0.75 * np.log(0.75))


def test_old_names_are_the_shared_ones():
    assert base.softmax is numerics.softmax and policies.softmax is numerics.softmax
    assert base.floor_log is numerics.floor_log and base.xlogx_sum is numerics.xlogx_sum
    assert genmodel.normalise is numerics.normalise and efe.xlogx is numerics.xlogx
    assert base.LOG_FLOOR == efe.EPS == numerics.LOG_FLOOR


def test_no_library_keeps_its_own_copy():
    pattern = re.compile(r"def (softmax|_softmax\w*|normalise|floor_log|xlogx)\(|np\.finfo\(float\)\.eps")
    copies = []
    for pkg in ("genmodel", "inference", "planning", "envs", "cogmap"):
        for path in (ROOT / pkg).rglob("*.py"):
            if path.name == "numerics.py" and path.parent.name == "genmodel":
                continue
            copies += [f"{path.relative_to(ROOT)}:{i}" for i, line in enumerate(path.read_text().splitlines(), 1)
                       if pattern.search(line)]
    assert copies == []
