"""Bad model specifications are refused with a SpecError naming the part and the problem."""

import numpy as np
import pytest

from cogmap.genmodel import Factor, Modality, ModelSpec, SparseB, SpecError, compile


def spec(**kw):
    d = dict(factors=[Factor("s", 2, 2)], modalities=[Modality("o", 2, ("s",))],
             A={"o": np.eye(2)}, B={"s": np.stack([np.eye(2)] * 2, -1)})
    d.update(kw)
    return ModelSpec(**d)


BAD = {
    "same factor twice": (dict(modalities=[Modality("o", 2, ("s", "s"))], A={"o": np.full((2, 2, 2), 0.5)}),
                          "modality 'o': depends on factor 's' twice"),
    "no factors": (dict(factors=[], modalities=[], A={}, B={}), "factors: empty"),
    "no modalities": (dict(modalities=[], A={}), "modalities: empty"),
    "NaN C": (dict(C={"o": [np.nan, 0.0]}), "C['o']: contains NaN or infinite"),
    "infinite C": (dict(C={"o": [np.inf, 0.0]}), "C['o']: contains NaN or infinite"),
    "complex A": (dict(A={"o": np.eye(2) + 0j}), "A['o']: complex entries"),
    "complex C": (dict(C={"o": [1 + 1j, 0]}), "C['o']: complex entries"),
    "string C": (dict(C={"o": ["a", "b"]}), "C['o']: not a numeric array (got strings)"),
    "object D": (dict(D={"s": [None, 1.0]}), "D['s']: not a numeric array"),
    "string size": (dict(factors=[Factor("s", "2", 2)]), "factor 's' size: must be an integer, got str"),
    "float size": (dict(factors=[Factor("s", 2.0, 2)]), "factor 's' size: must be an integer, got float"),
    "float controls": (dict(factors=[Factor("s", 2, 2.0)]), "factor 's' num_controls: must be an integer"),
    "string modality size": (dict(modalities=[Modality("o", "2", ("s",))]), "modality 'o' size: must be an integer"),
    "A as a list": (dict(A=[np.eye(2)]), "A: expected a dict keyed by name, got list"),
    "ragged A": (dict(A={"o": [[1, 0], [0]]}), "A['o']: not a numeric array (nested lists of unequal"),
    "A nested list, wrong shape": (dict(A={"o": [[1.0, 1.0]]}), "A['o']: shape (1, 2), expected (2, 2)"),
    "huge dense capacity": (dict(factors=[Factor("s", 2, 2, growable=True, capacity=10**6)]),
                            "B['s']: capacity shape (1000000, 1000000, 2) needs 2e+12 entries"),
    "float capacity": (dict(factors=[Factor("s", 2, 2, growable=True, capacity=8.0)]),
                       "factor 's' capacity: must be an integer"),
    "NaN collision preference": (dict(collision_preference=float("nan")),
                                 "collision_preference: must be a finite number (a log-preference) or None, got nan"),
    "string collision preference": (dict(collision_preference="-10"), "collision_preference: must be a finite number"),
    # learning sets B's columns to the normalised counts: a zero count where B is positive contradicts B
    "pB zero where B is positive": (dict(pB={"s": np.stack([np.eye(2), np.eye(2)[::-1]], -1)}),
                                    "pB['s']: count 0 at (next 0, current 0, control 1) where B['s'] is 1; learning "
                                    "sets each column of B to its normalised counts, so the counts must be positive "
                                    "wherever B is"),
    "pB column of zeros": (dict(pB={"s": np.stack([np.eye(2), np.diag([1.0, 0.0])], -1)}),
                           "pB['s']: count 0 at (next 1, current 1, control 1) where B['s'] is 1"),
    "sparse counts zero where B is positive": (
        dict(B={"s": SparseB(np.array([[[0, 1], [0, 1]], [[1, 0], [1, 0]]]), np.full((2, 2, 2), 0.5),
                             np.array([[[1.0, 0.0], [1.0, 1.0]], [[1.0, 1.0], [1.0, 1.0]]]))}),
        "B['s'].counts: count 0 at (state 0, control 0, slot 1) where B['s'] is 0.5"),
}


def test_pB_with_counts_where_B_is_zero_is_a_prior_and_accepted():
    """pB positive where B is 0 (a soft prior, as pymdp's): the move becomes possible once learnt."""
    model = compile(spec(pB={"s": np.stack([np.eye(2)] * 2, -1) * 2 + 0.1}))
    assert model.live_pB(0)[1, 0, 0] == pytest.approx(0.1) and model.live_B(0)[1, 0, 0] == 0


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_spec_is_refused_with_a_clear_message(case):
    kw, message = BAD[case]
    with pytest.raises(SpecError) as err:
        compile(spec(**kw))
    assert message in str(err.value)


def test_capacity_limit_names_the_factor_suggests_sparse_and_is_configurable():
    s = spec(factors=[Factor("place", 2, 2, growable=True, capacity=4096)],
             modalities=[Modality("o", 2, ("place",))], B={"place": np.stack([np.eye(2)] * 2, -1)})
    with pytest.raises(SpecError, match=r"B\['place'\].*SparseB"):
        compile(s, max_entries=10**6)
    model = compile(s)  # 4096 x 4096 x 2 is under the default limit
    assert model.state_capacity(0) == 4096


def test_sparse_transitions_at_a_large_capacity_are_accepted():
    succ = np.broadcast_to(np.arange(2)[:, None, None], (2, 2, 1)).copy()
    s = spec(factors=[Factor("s", 2, 2, growable=True, capacity=10**6)],
             B={"s": SparseB(succ, np.ones((2, 2, 1)))},
             modalities=[Modality("o", 2, ("s",))])
    from cogmap.genmodel import SparseA

    s.A = {"o": SparseA(prior=np.ones(2))}
    model = compile(s)
    assert model.state_capacity(0) == 10**6


def test_running_out_of_memory_under_the_limit_is_a_spec_error(monkeypatch):
    import sys

    comp = sys.modules["cogmap.genmodel.compile"]  # the module (the package exports the function)

    def no_memory(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(comp, "_fill_dead_columns", no_memory)  # as if the dense A could not be allocated
    with pytest.raises(SpecError, match="not enough memory .* SparseA/SparseB"):
        compile(spec())
