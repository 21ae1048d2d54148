"""Observation encoders: image -> observation id.

The generative model only sees observation ids, so any function ``image -> (id, is_new)`` can
serve (section 3.1, sensor agnosticism). :class:`SSIMEncoder` is the paper's: a panorama is
matched against the stored ones by structural similarity (Wang et al. 2004, Gaussian window
11 / sigma 1.5) and a score below the threshold (0.65) makes it a new observation.

Encoders are chosen by name: ``AgentConfig(encoder="ssim")`` (the default) and
:func:`register_encoder` adds a factory ``factory(config) -> Encoder`` under a new name, which
:class:`~cogmap.agent.aimapp.AIMAPPAgent` (and so ``cogmap.explore``) then builds.

Per-image statistics (local means and variances) are cached when an image is stored, and the
stored images are compared in channel-stacked batches, so one query against hundreds of stored
panoramas costs a handful of OpenCV calls.
"""

from __future__ import annotations

import numpy as np

from cogmap.genmodel import contracts
from cogmap.genmodel.contracts import Encoder
from cogmap.genmodel.registry import Registry

C1 = (0.01 * 255) ** 2
C2 = (0.03 * 255) ** 2
BATCH = 128  # OpenCV 5 refuses GaussianBlur on more than 128 channels


def check_encoder(encoder) -> None:
    """A clear error naming what an encoder lacks of the :class:`Encoder` protocol.

    Parameters
    ----------
    encoder : object
        The object to check: it needs ``images``, ``last_scores``, ``__call__`` and ``match``.

    Raises
    ------
    TypeError
        Naming the missing members.
    """
    missing = [name for name in ("images", "last_scores", "__call__", "match") if not hasattr(encoder, name)]
    if missing:
        raise TypeError(f"{type(encoder).__name__} is not an Encoder: it lacks {', '.join(missing)}")


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


THUMB = (8, 32)  # thumbnail (rows, cols) used to shortlist candidates


def _thumb(x: np.ndarray) -> np.ndarray:
    """Zero-mean, unit-norm grey thumbnail: its dot products are normalised correlations."""
    t = _cv2().resize(x, (THUMB[1], THUMB[0]), interpolation=_cv2().INTER_AREA).ravel()
    t = t - t.mean()
    return (t / max(float(np.linalg.norm(t)), 1e-6)).astype(np.float32)


def _blur(x: np.ndarray) -> np.ndarray:
    return _cv2().GaussianBlur(x, (11, 11), 1.5, borderType=4)  # BORDER_REFLECT_101


def ssim(a: np.ndarray, b: np.ndarray) -> float:
    """Mean structural similarity of two images (Wang et al. 2004; section 3.1, Table 6).

    Local means, variances and covariance use an 11 x 11 Gaussian window of sigma 1.5 (borders
    reflected), with the constants ``C1 = (0.01 * 255)**2`` and ``C2 = (0.03 * 255)**2``.

    Parameters
    ----------
    a, b : numpy.ndarray
        Images of the same size, ``(H, W)`` grey or ``(H, W, C)`` RGB(A) (turned grey with the
        BT.601 weights), grey levels 0-255.

    Returns
    -------
    float
        Mean SSIM over the pixels, at most 1 (identical images); the paper's encoder treats a
        score of at least 0.65 as the same observation.
    """
    x, y = _gray(a), _gray(b)
    mx, my = _blur(x), _blur(y)
    vx, vy = _blur(x * x) - mx * mx, _blur(y * y) - my * my
    cxy = _blur(x * y) - mx * my
    num = (2 * mx * my + C1) * (2 * cxy + C2)
    den = (mx * mx + my * my + C1) * (vx + vy + C2)
    return float(np.mean(num / den))


def column_shift_scores(a: np.ndarray, b: np.ndarray, rows: int = 16) -> np.ndarray:
    """Normalised correlation of ``np.roll(a, s, axis=1)`` with ``b`` for every column shift
    ``s`` (index ``s`` of the result, ``0 <= s < width``), for 360-degree panoramas.

    Both images are reduced to ``rows`` grey rows (area average) with each row's mean removed;
    the circular cross-correlation of the rows is summed (one FFT per image), so every shift
    costs nothing extra. Used to shortlist the shifts worth an SSIM.

    Parameters
    ----------
    a, b : numpy.ndarray
        Panoramas of the same shape, ``(H, W)`` grey or ``(H, W, C)`` RGB; the columns span 360
        degrees, so one column is ``360 / W`` degrees of heading.
    rows : int, optional
        Number of rows the images are reduced to, default 16.

    Returns
    -------
    numpy.ndarray
        ``(W,)`` float correlations in [-1, 1]; entry ``s`` is for the shift ``s`` (a negative
        shift ``-s`` is entry ``W - s``).

    Raises
    ------
    ValueError
        When the two images differ in shape.
    """
    x, y = _gray(a), _gray(b)
    if x.shape != y.shape:
        raise ValueError(f"images of shapes {x.shape} and {y.shape} differ")
    w = x.shape[1]
    x = _cv2().resize(x, (w, rows), interpolation=_cv2().INTER_AREA).astype(float)
    y = _cv2().resize(y, (w, rows), interpolation=_cv2().INTER_AREA).astype(float)
    x -= x.mean(axis=1, keepdims=True)
    y -= y.mean(axis=1, keepdims=True)
    # r[s] = sum_c x[c - s] y[c] = correlation of roll(x, s) with y
    r = np.fft.irfft(np.fft.rfft(y, axis=1) * np.conj(np.fft.rfft(x, axis=1)), n=w, axis=1).sum(axis=0)
    return r / max(float(np.linalg.norm(x) * np.linalg.norm(y)), 1e-9)


def signed_shifts(max_shift: int, width: int) -> np.ndarray:
    """Column shifts ``-max_shift .. max_shift`` (clipped to half the width).

    Parameters
    ----------
    max_shift : int
        Largest shift searched, columns.
    width : int
        Panorama width, columns.

    Returns
    -------
    numpy.ndarray
        ``(2 m + 1,)`` int shifts ``-m .. m`` with ``m = min(max_shift, width // 2)``.
    """
    m = min(int(max_shift), width // 2)
    return np.arange(-m, m + 1)


def shifted_ssim(a: np.ndarray, b: np.ndarray, shifts) -> np.ndarray:
    """SSIM of ``np.roll(a, s, axis=1)`` with ``b`` for each shift ``s`` (exhaustive reference).

    Parameters
    ----------
    a, b : numpy.ndarray
        Panoramas of the same shape, ``(H, W)`` grey or ``(H, W, C)`` RGB, grey levels 0-255.
    shifts : int or array_like of int
        Column shifts applied to ``a``.

    Returns
    -------
    numpy.ndarray
        ``(len(shifts),)`` float: :func:`ssim` for each shift.
    """
    return np.array([ssim(np.roll(_gray(a), int(s), axis=1), b) for s in np.atleast_1d(shifts)])


def best_shift(a: np.ndarray, b: np.ndarray, max_shift: int, refine: int = 3) -> tuple[int, float]:
    """The column shift ``s`` (``|s| <= max_shift``) for which ``np.roll(a, s, axis=1)`` best
    matches ``b``, and that SSIM: the ``refine`` shifts with the best row correlation
    (:func:`column_shift_scores`) are scored by SSIM.

    Parameters
    ----------
    a, b : numpy.ndarray
        Panoramas of the same shape, ``(H, W)`` grey or ``(H, W, C)`` RGB, grey levels 0-255.
    max_shift : int
        Largest shift searched, columns (clipped to ``W // 2``; one column is ``360 / W``
        degrees).
    refine : int, optional
        Number of shifts scored by SSIM, default 3.

    Returns
    -------
    shift : int
        The best of the scored shifts, columns.
    score : float
        Its SSIM.

    Raises
    ------
    ValueError
        When the two images differ in shape.
    """
    x = _gray(a)
    corr = column_shift_scores(x, b)
    shifts = signed_shifts(max_shift, x.shape[1])
    top = shifts[np.argsort(-corr[shifts % x.shape[1]], kind="stable")[:refine]]
    scores = shifted_ssim(x, b, top)
    k = int(np.argmax(scores))
    return int(top[k]), float(scores[k])


class SSIMEncoder:
    """Match panoramas by SSIM; unmatched panoramas become new observation ids.

    Stored images and their local statistics live in arrays ``(capacity, H, W)`` that double
    when full. A query first shortlists the stored images whose grey thumbnails correlate best
    with it, then computes SSIM against those in channel-stacked batches (one blur of the cross
    products per batch of up to 128 images).

    Parameters
    ----------
    threshold : float, optional
        In [0, 1]: a query whose best SSIM is at least this is the stored observation; below
        it, a new one (Table 6: 0.65, the default).
    shortlist : int or None, optional
        SSIM only this many stored images, the best by thumbnail correlation (default 24);
        None compares with all of them.

    Attributes
    ----------
    images : list of numpy.ndarray
        The stored images in id order (copies of what was given, e.g. ``(H, W, 3)`` uint8 RGB).
    last_scores : numpy.ndarray
        ``(k,)`` SSIM of the latest :meth:`match` query against the ``k`` shortlisted ids.
    """

    def __init__(self, threshold: float = 0.65, shortlist: int | None = 24):
        self.threshold = threshold
        self.shortlist = shortlist  # SSIM only the best few by thumbnail correlation (None: all)
        self.images: list[np.ndarray] = []
        self._x = self._mu = self._mu2c1 = self._varc2 = None  # (capacity, H, W) float32
        self._thumbs = np.zeros((0, THUMB[0] * THUMB[1]), dtype=np.float32)
        self.last_scores = np.zeros(0)

    def __len__(self) -> int:
        return len(self.images)

    def _reserve(self, shape: tuple[int, int]) -> None:
        n = len(self.images)
        if self._x is not None and n < self._x.shape[0]:
            return
        cap = max(8, 2 * n)
        for name in ("_x", "_mu", "_mu2c1", "_varc2"):
            new = np.zeros((cap,) + shape, dtype=np.float32)
            old = getattr(self, name)
            if old is not None:
                new[:n] = old[:n]
            setattr(self, name, new)

    def add(self, image: np.ndarray) -> int:
        """Store ``image`` as a new observation.

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W)`` grey or ``(H, W, C)`` RGB image, grey levels 0-255; every stored image
            has the same ``(H, W)``.

        Returns
        -------
        int
            Its observation id (the number of images stored before it).

        Raises
        ------
        ValueError
            When its size differs from the stored images'.
        """
        x = _gray(image)
        if self.images and x.shape != self._x.shape[1:]:
            raise ValueError(f"image of shape {x.shape} does not match stored {self._x.shape[1:]}")
        self._reserve(x.shape)
        k = len(self.images)
        mu = _blur(x)
        self._x[k] = x
        self._mu[k] = mu
        self._mu2c1[k] = mu * mu + C1
        self._varc2[k] = _blur(x * x) - mu * mu + C2
        self._thumbs = np.vstack([self._thumbs, _thumb(x)])
        self.images.append(np.asarray(image).copy())
        return k

    def scores(self, image: np.ndarray, ids: np.ndarray | None = None) -> np.ndarray:
        """SSIM of ``image`` against the stored images ``ids`` (as :func:`ssim`, batched).

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W)`` grey or ``(H, W, C)`` RGB query, the stored images' size.
        ids : array_like of int or None, optional
            Stored ids to compare with; None (default) for all.

        Returns
        -------
        numpy.ndarray
            ``(len(ids),)`` float SSIM in the order of ``ids``; empty when nothing is stored.

        Raises
        ------
        ValueError
            When the query's size differs from the stored images'.
        """
        n = len(self.images)
        if n == 0:
            return np.zeros(0)
        x = _gray(image)
        if x.shape != self._x.shape[1:]:
            raise ValueError(f"image of shape {x.shape} does not match stored {self._x.shape[1:]}")
        mx = _blur(x)
        vx = _blur(x * x) - mx * mx
        ids = np.arange(n) if ids is None else np.asarray(ids, dtype=int)
        out = np.empty(ids.size)
        for a in range(0, ids.size, BATCH):
            sel = ids[a : a + BATCH]
            prod = (x[None] * self._x[sel]).transpose(1, 2, 0)  # (H, W, k) for the channel-wise blur
            cxy = np.ascontiguousarray(_blur(np.ascontiguousarray(prod)).reshape(prod.shape).transpose(2, 0, 1))
            mxy = mx[None] * self._mu[sel]
            cxy -= mxy  # local covariance
            num = (2 * mxy + C1) * (2 * cxy + C2)
            den = ((mx * mx)[None] + self._mu2c1[sel]) * (vx[None] + self._varc2[sel])
            out[a : a + sel.size] = (num / den).mean(axis=(1, 2))
        return out

    def align(self, image: np.ndarray, ids, max_shift: int, refine: int = 3) -> tuple[int, int, float]:
        """Best match of ``image`` among stored ``ids`` allowing a circular column shift of up to
        ``max_shift`` columns: returns ``(id, shift, ssim)`` where ``np.roll(image, shift, axis=1)``
        is what matched (``(-1, 0, 0.0)`` for no ids).

        Per stored image, the ``refine`` shifts with the best row correlation
        (:func:`column_shift_scores`) are scored by SSIM; a heading error of the panorama's
        reference direction shows up as such a shift (one column = 360 / width degrees).

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W)`` grey or ``(H, W, C)`` RGB panorama, the stored images' size.
        ids : int or array_like of int
            Stored ids to compare with.
        max_shift : int
            Largest column shift searched.
        refine : int, optional
            Shifts scored by SSIM per stored image, default 3.

        Returns
        -------
        id : int
            The best-matching stored id; -1 when ``ids`` is empty (or no SSIM is positive).
        shift : int
            Column shift applied to ``image`` for that match.
        ssim : float
            That SSIM (0.0 with id -1).
        """
        x = _gray(image)
        best = (-1, 0, 0.0)
        for k in np.atleast_1d(np.asarray(ids, dtype=int)):
            shift, score = best_shift(x, self._x[k], max_shift, refine)
            if score > best[2]:
                best = (int(k), shift, score)
        return best

    def candidates(self, image: np.ndarray) -> np.ndarray:
        """Stored ids worth an SSIM: all, or the ``shortlist`` best by thumbnail correlation.

        Parameters
        ----------
        image : numpy.ndarray
            ``(H, W)`` grey or ``(H, W, C)`` RGB query.

        Returns
        -------
        numpy.ndarray
            Sorted int ids: every stored id when ``shortlist`` is None or not exceeded, else the
            ``shortlist`` ids whose 8 x 32 grey thumbnails correlate best with the query's.
        """
        n = len(self.images)
        if self.shortlist is None or n <= self.shortlist:
            return np.arange(n)
        corr = self._thumbs[:n] @ _thumb(_gray(image))
        return np.sort(np.argpartition(-corr, self.shortlist)[: self.shortlist])

    def match(self, image: np.ndarray) -> tuple[int, float]:
        """Best stored id by SSIM among the :meth:`candidates`; stores nothing.

        Sets :attr:`last_scores` to the SSIM of every candidate.

        Parameters
        ----------
        image : numpy.ndarray
            The query, as for :meth:`candidates`.

        Returns
        -------
        id : int
            The best stored id; -1 when nothing is stored.
        score : float
            Its SSIM (0.0 when nothing is stored).
        """
        ids = self.candidates(image)
        s = self.scores(image, ids)
        self.last_scores = s
        if s.size == 0:
            return -1, 0.0
        best = int(np.argmax(s))
        return int(ids[best]), float(s[best])

    def __call__(self, image: np.ndarray) -> tuple[int, bool]:
        best, score = self.match(image)
        if best >= 0 and score >= self.threshold:
            return best, False
        return self.add(image), True


# -- encoders by name ----------------------------------------------------------------------------
def _ssim_encoder(config) -> SSIMEncoder:
    """The paper's encoder (section 3.1) with the configured threshold (Table 6: 0.65).

    Parameters
    ----------
    config : AgentConfig
        Reads ``ssim_threshold``.

    Returns
    -------
    SSIMEncoder
        A new, empty encoder.
    """
    return SSIMEncoder(config.ssim_threshold)


def _not_an_encoder(name: str, factory) -> None:
    if callable(factory) and isinstance(factory, Encoder):
        raise TypeError(f"register_encoder('{name}'): expected a callable factory(config) -> Encoder, got the "
                        f"encoder {type(factory).__name__} itself (register lambda config: ... returning a new one)")


#: the registered encoder factories ``factory(config: AgentConfig) -> Encoder`` (called once per
#: agent); ``register_encoder(name, factory, *, overwrite=False)`` (``AgentConfig(encoder=name)``
#: then selects it), ``unregister_encoder`` and ``available_encoders`` are its methods. The
#: built-in ``"ssim"`` can be neither replaced nor removed.
ENCODERS = Registry("encoder", "register_encoder", protocol=contracts.EncoderFactory,
                    expected="a callable factory(config) -> Encoder", check=_not_an_encoder)
ENCODERS.add("ssim", _ssim_encoder)
ENCODERS.seal()
register_encoder = ENCODERS.register
unregister_encoder = ENCODERS.remove
available_encoders = ENCODERS.available


def make_encoder(name: str, config) -> Encoder:
    """Build the encoder registered as ``name`` and check it follows :class:`Encoder`.

    Parameters
    ----------
    name : str
        A registered encoder name (``AgentConfig.encoder``).
    config : AgentConfig
        Passed to the factory.

    Returns
    -------
    Encoder
        A new encoder.

    Raises
    ------
    KeyError
        Unknown name; the message lists the registered ones.
    TypeError
        The factory's result lacks a member of the :class:`Encoder` protocol.
    """
    encoder = ENCODERS.get(name)(config)
    check_encoder(encoder)
    return encoder

