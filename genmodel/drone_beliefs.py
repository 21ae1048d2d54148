"""The drone's binned state factors and the kernel-belief model (DRONE.md 2.4).

Five factors, each a categorical belief over fixed bins: distance to the target (75 bins on
[0, 125] m), azimuth (50 on [-pi, pi], circular) and elevation (50 on [-pi/2, pi/2]) of the target
in the drone's egocentric frame, suitability and density (50 each on [0, 1]). Bin centres are the
``length``-point ranges of the original (``range(lo, hi, length=n)``, both ends included).
Observations are continuous values; the Gaussian-kernel update that turns them into beliefs is the
``"kernel"`` inference scheme (:mod:`cogmap.inference.kernel_filter`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

BASE_WIDTH = 0.1  # w of DRONE.md 2.4
MAX_DISTANCE = 125.0


@dataclass(frozen=True)
class BinnedFactor:
    """One factor: ``n`` bin centres on [lo, hi]; ``circular`` factors use wrapped differences."""

    name: str
    lo: float
    hi: float
    n: int
    circular: bool = False

    def __post_init__(self):
        if self.n < 2 or not self.hi > self.lo:
            raise ValueError(f"factor '{self.name}': need n >= 2 and hi > lo (got n={self.n}, [{self.lo}, {self.hi}])")

    @cached_property
    def bins(self) -> np.ndarray:
        b = np.linspace(self.lo, self.hi, self.n)
        b.flags.writeable = False
        return b

    def difference(self, obs: float) -> np.ndarray:
        """bin - obs, wrapped to (-pi, pi] for circular factors."""
        d = self.bins - float(obs)
        if self.circular:
            d = np.arctan2(np.sin(d), np.cos(d))
        return d


def kernel_width(name: str, obs: float, w: float = BASE_WIDTH) -> float:
    """Kernel width per factor: distance w (1 + 0.5 d / 100), azimuth/elevation 2 w, others w."""
    if name == "distance":
        return w * (1.0 + 0.5 * float(obs) / 100.0)
    if name in ("azimuth", "elevation"):
        return 2.0 * w
    return w


DRONE_FACTORS = (
    BinnedFactor("distance", 0.0, MAX_DISTANCE, 75),
    BinnedFactor("azimuth", -np.pi, np.pi, 50, circular=True),
    BinnedFactor("elevation", -np.pi / 2, np.pi / 2, 50),
    BinnedFactor("suitability", 0.0, 1.0, 50),
    BinnedFactor("density", 0.0, 1.0, 50),
)


@dataclass(frozen=True)
class KernelBeliefModel:
    """Binned factors plus the update constants: b = (1 - rate) b + rate L, kernel base width,
    and the target weighting of the distance factor (b_d *= 1 + exp(-d/10) (125 - bin)/125)."""

    factors: tuple[BinnedFactor, ...] = field(default_factory=lambda: DRONE_FACTORS)
    rate: float = 0.2
    width: float = BASE_WIDTH
    target_weighting: bool = True

    def __post_init__(self):
        if not 0.0 < self.rate <= 1.0:
            raise ValueError(f"KernelBeliefModel: rate must be in (0, 1], got {self.rate}")
        if self.width <= 0:
            raise ValueError(f"KernelBeliefModel: width must be positive, got {self.width}")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.factors)

    def uniform(self) -> list[np.ndarray]:
        return [np.full(f.n, 1.0 / f.n) for f in self.factors]


def entropy(b) -> float:
    """Shannon entropy (nats) of a categorical belief."""
    b = np.asarray(b, float)
    nz = b[b > 0]
    return float(-(nz * np.log(nz)).sum())


def expected_state(model: KernelBeliefModel, beliefs) -> dict[str, float]:
    """Belief means per factor (circular mean for circular factors)."""
    out = {}
    for f, b in zip(model.factors, beliefs, strict=True):
        if f.circular:
            out[f.name] = float(np.arctan2(b @ np.sin(f.bins), b @ np.cos(f.bins)))
        else:
            out[f.name] = float(b @ f.bins)
    return out


def normalised_entropy(model: KernelBeliefModel, beliefs, name: str) -> float:
    """Entropy of one factor divided by ln(#bins)."""
    i = model.names.index(name)
    return entropy(beliefs[i]) / np.log(model.factors[i].n)


def egocentric_state(position, target, heading: float = 0.0) -> dict[str, float]:
    """Distance, azimuth (relative to ``heading``, wrapped) and elevation of the target seen from
    ``position`` (z up)."""
    d = np.asarray(target, float) - np.asarray(position, float)
    horiz = float(np.hypot(d[0], d[1]))
    az = float(np.arctan2(d[1], d[0]) - heading)
    return {"distance": float(np.linalg.norm(d)), "azimuth": float(np.arctan2(np.sin(az), np.cos(az))),
            "elevation": float(np.arctan2(d[2], horiz))}
