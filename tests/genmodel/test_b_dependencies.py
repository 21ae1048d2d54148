"""Compiling factors whose transitions depend on several factors (``Factor.depends_on``)."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap.genmodel import compile
from cogmap.genmodel.spec import Factor, Modality, ModelSpec, SparseB, SpecError


def _spec(b_shape=(2, 3, 2, 2), depends_on=("a", "b"), B_b=None, **kw):
    rng = np.random.default_rng(0)
    b = rng.random(b_shape) + 0.1
    b /= b.sum(axis=0, keepdims=True)
    factors = [Factor("a", 3, 2, **kw.pop("a_kw", {})), Factor("b", 2, 2, depends_on=depends_on, **kw.pop("b_kw", {}))]
    return ModelSpec(factors, [Modality("o", 2, ("b",))], A={"o": np.eye(2)},
                     B={"a": np.repeat(np.eye(3)[:, :, None], 2, axis=2), "b": b if B_b is None else B_b}, **kw)


def test_compiles_and_stores_the_dependencies():
    m = compile(_spec())
    assert m.B_deps == ((0,), (0, 1))
    assert m.live_B(1).shape == (2, 3, 2, 2)
    # the factor itself first or not: the axes follow depends_on
    m2 = compile(_spec(b_shape=(2, 2, 3, 2), depends_on=("b", "a")))
    assert m2.B_deps == ((0,), (1, 0))
    # depending on itself alone is the ordinary layout
    m3 = compile(_spec(b_shape=(2, 2, 2), depends_on=("b",)))
    assert m3.B_deps == ((0,), (1,)) and not m3.has_B_deps


def test_wrong_shape():
    with pytest.raises(SpecError, match=r"B\['b'\]: shape \(2, 2, 2\), expected \(2, 3, 2, 2\) "
                                        r"\(next, \*depends_on \['a', 'b'\], control\)"):
        compile(_spec(b_shape=(2, 2, 2)))


def test_not_normalised():
    b = np.full((2, 3, 2, 2), 0.5)
    b[:, 1, 0, 1] = [0.5, 0.7]
    with pytest.raises(SpecError, match=r"B\['b'\]: column \(1, 0, 1\) sums to 1.2, expected 1"):
        compile(_spec(B_b=b))


def test_negative_or_nan_entries():
    b = np.full((2, 3, 2, 2), 0.5)
    b[0, 0, 0, 0] = -0.5
    with pytest.raises(SpecError, match=r"B\['b'\]: contains negative entries"):
        compile(_spec(B_b=b))
    b[0, 0, 0, 0] = np.nan
    with pytest.raises(SpecError, match=r"B\['b'\]: contains NaN or infinite entries"):
        compile(_spec(B_b=b))


def test_own_factor_must_be_a_dependency():
    with pytest.raises(SpecError, match=r"factor 'b': depends_on \['a'\] must include the factor itself \('b'\)"):
        compile(_spec(b_shape=(2, 3, 2), depends_on=("a",)))


def test_malformed_dependencies():
    with pytest.raises(SpecError, match="factor 'b': depends on missing factor 'z'"):
        compile(_spec(depends_on=("b", "z")))
    with pytest.raises(SpecError, match="factor 'b': depends on factor 'b' twice"):
        compile(_spec(depends_on=("b", "b")))
    with pytest.raises(SpecError, match="factor 'b': depends_on must be a tuple of factor names"):
        compile(_spec(depends_on="b"))
    with pytest.raises(SpecError, match="factor 'b': depends_on is empty"):
        compile(_spec(depends_on=()))


def test_sparse_growable_and_padded_refused():
    sparse = SparseB(np.zeros((2, 2, 1), dtype=int) + np.arange(2)[:, None, None], np.ones((2, 2, 1)))
    with pytest.raises(SpecError, match=r"B\['b'\]: a SparseB cannot depend on other factors"):
        compile(_spec(B_b=sparse))
    with pytest.raises(SpecError, match="factor 'b': depends_on .* only supported between factors of fixed size "
                                        r"\(factor 'a' is growable\)"):
        compile(_spec(a_kw={"growable": True}))
    with pytest.raises(SpecError, match=r"\(it is padded to capacity 4\)"):
        compile(_spec(b_kw={"capacity": 4}))


def test_pB_shape_and_support():
    spec = _spec()
    spec.pB["b"] = np.ones((2, 2, 2))
    with pytest.raises(SpecError, match=r"pB\['b'\]: shape \(2, 2, 2\), expected \(2, 3, 2, 2\)"):
        compile(spec)
    spec.pB["b"] = np.ones((2, 3, 2, 2))
    spec.pB["b"][1, 2, 0, 1] = 0.0
    with pytest.raises(SpecError, match=r"pB\['b'\]: count 0 at \(1, 2, 0, 1\)"):
        compile(spec)
    spec.pB["b"][1, 2, 0, 1] = 3.0
    m = compile(spec)
    assert m.live_pB(1)[1, 2, 0, 1] == 3.0


def test_stay_control_must_keep_the_own_state():
    b = np.zeros((2, 3, 2, 2))
    b[:, :, :, 0] = np.eye(2)[:, None, :]  # control 0 keeps b whatever a is
    b[:, :, :, 1] = 0.5
    m = compile(_spec(B_b=b, b_kw={"stay": 0}))
    assert m.B_deps[1] == (0, 1)
    with pytest.raises(SpecError, match=r"B\['b'\]: stay control 1 must keep the factor's own state"):
        compile(_spec(B_b=b, b_kw={"stay": 1}))


def test_single_factor_operations_refuse():
    m = compile(_spec())
    with pytest.raises(SpecError, match=r"factor 'b': its transitions depend on the factors \[0, 1\]"):
        m.predict(1, np.full(2, 0.5), 0)
    with pytest.raises(SpecError, match="B_dependencies"):
        m.B[1].learn_soft(np.ones(2), np.ones(2), 0, 1.0, 2)


def test_jax_backend_refuses():
    pytest.importorskip("jax")
    from cogmap.genmodel.jax_model import to_jax

    with pytest.raises(SpecError, match=r"the JAX backend \(to_jax\) does not support transitions that depend "
                                        r"on several factors \(B_dependencies \{'b': \['a', 'b'\]\}\)"):
        to_jax(compile(_spec()))


def test_save_and_load_round_trip(tmp_path):
    from cogmap.genmodel.io import load, save

    m = compile(_spec())
    path = tmp_path / "m"
    save(m, path)
    back = load(path)
    assert back.B_deps == m.B_deps
    np.testing.assert_array_equal(back.live_B(1), m.live_B(1))
