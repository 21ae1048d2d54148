import pytest

from cogmap.envs.sim import NavSim


@pytest.fixture
def make_sim():
    sims = []

    def _make(*args, **kwargs):
        sim = NavSim(*args, **kwargs)
        sims.append(sim)
        return sim

    yield _make
    for s in sims:
        s.close()
