"""Observation encoders: image -> observation id.

The generative model only sees observation ids, so any function ``image -> (id, is_new)`` can
serve (section 3.1, sensor agnosticism). :class:`SSIMEncoder` is the paper's: a panorama is
matched against the stored ones by structural similarity (Wang et al. 2004, Gaussian window
11 / sigma 1.5) and a score below the threshold (0.65) makes it a new observation.

Per-image statistics (local means and variances) are cached when an image is stored, and the
stored images are compared in channel-stacked batches, so one query against hundreds of stored
panoramas costs a handful of OpenCV calls.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

C1 = (0.01 * 255) ** 2
C2 = (0.03 * 255) ** 2
BATCH = 128  # OpenCV 5 refuses GaussianBlur on more than 128 channels


class Encoder(Protocol):
    def __call__(self, image: np.ndarray) -> tuple[int, bool]:
        """Return (observation id, whether the id is new)."""


def _cv2():
    try:
        import cv2
    except ImportError as err:  # pragma: no cover - depends on the install
        raise ImportError("SSIMEncoder needs OpenCV: pip install 'cogmap[sim]'") from err
    return cv2


def _gray(image: np.ndarray) -> np.ndarray:
    img = np.asarray(image)
    if img.ndim == 3:
        img = img[..., :3].astype(np.float32) @ np.array([0.299, 0.587, 0.114], dtype=np.float32)
    return np.ascontiguousarray(img, dtype=np.float32)


def _blur(x: np.ndarray) -> np.ndarray:
    return _cv2().GaussianBlur(x, (11, 11), 1.5, borderType=4)  # BORDER_REFLECT_101


def ssim(a: np.ndarray, b: np.ndarray) -> float:
    """Mean structural similarity of two images (grey levels 0-255)."""
    x, y = _gray(a), _gray(b)
    mx, my = _blur(x), _blur(y)
    vx, vy = _blur(x * x) - mx * mx, _blur(y * y) - my * my
    cxy = _blur(x * y) - mx * my
    num = (2 * mx * my + C1) * (2 * cxy + C2)
    den = (mx * mx + my * my + C1) * (vx + vy + C2)
    return float(np.mean(num / den))


class SSIMEncoder:
    """Match panoramas by SSIM; unmatched panoramas become new observation ids."""

    def __init__(self, threshold: float = 0.65):
        self.threshold = threshold
        self.images: list[np.ndarray] = []
        self._x: list[np.ndarray] = []  # cached grey images and their local statistics
        self._mu: list[np.ndarray] = []
        self._var: list[np.ndarray] = []
        self.last_scores = np.zeros(0)

    def __len__(self) -> int:
        return len(self.images)

    def add(self, image: np.ndarray) -> int:
        """Store ``image`` as a new observation; returns its id."""
        x = _gray(image)
        mu = _blur(x)
        self.images.append(np.asarray(image).copy())
        self._x.append(x)
        self._mu.append(mu)
        self._var.append(_blur(x * x) - mu * mu)
        return len(self.images) - 1

    def scores(self, image: np.ndarray) -> np.ndarray:
        """SSIM of ``image`` against every stored image."""
        if not self.images:
            return np.zeros(0)
        x = _gray(image)
        if x.shape != self._x[0].shape:
            raise ValueError(f"image of shape {x.shape} does not match stored {self._x[0].shape}")
        mx = _blur(x)
        vx = _blur(x * x) - mx * mx
        out = np.empty(len(self.images))
        for start in range(0, len(self.images), BATCH):
            ys = np.stack(self._x[start : start + BATCH], axis=-1)
            mys = np.stack(self._mu[start : start + BATCH], axis=-1)
            vys = np.stack(self._var[start : start + BATCH], axis=-1)
            cxy = _blur(np.ascontiguousarray(x[..., None] * ys))
            if cxy.ndim == 2:
                cxy = cxy[..., None]
            cxy = cxy - mx[..., None] * mys
            num = (2 * mx[..., None] * mys + C1) * (2 * cxy + C2)
            den = (mx[..., None] ** 2 + mys**2 + C1) * (vx[..., None] + vys + C2)
            out[start : start + ys.shape[-1]] = (num / den).mean(axis=(0, 1))
        return out

    def match(self, image: np.ndarray) -> tuple[int, float]:
        """Best stored id and its score (-1, 0.0 when nothing is stored)."""
        s = self.scores(image)
        self.last_scores = s
        if s.size == 0:
            return -1, 0.0
        best = int(np.argmax(s))
        return best, float(s[best])

    def __call__(self, image: np.ndarray) -> tuple[int, bool]:
        best, score = self.match(image)
        if best >= 0 and score >= self.threshold:
            return best, False
        return self.add(image), True
