"""Pictures of a drone flight: top-down (x-y) and side (along the start-target line vs altitude)."""

from __future__ import annotations

import numpy as np

from .drone_field import Field


def _draw_topdown(ax, field: Field, path=None, target=None, title=None, window=None):
    from matplotlib.patches import Circle, Rectangle

    for b in field.blocks:
        ax.add_patch(Rectangle((b.x - b.sx / 2, b.y - b.sy / 2), b.sx, b.sy,
                               fc="#b07050" if b.kind == "house" else "#8a6a5a", ec="k", lw=0.3))
    for c in field.crowns:
        ax.add_patch(Circle((c.x, c.y), c.radius, fc="#4c9a4c", ec="#2d5e2d", lw=0.3, alpha=0.8))
    if path is not None and len(path):
        P = np.asarray(path)
        ax.plot(P[:, 0], P[:, 1], "-", c="tab:blue", lw=1.2, zorder=5)
    s = field.start
    ax.plot(s[0], s[1], "k^", ms=7, zorder=6, label="start")
    if target is not None:
        ax.plot(target[0], target[1], "r*", ms=12, zorder=6, label="target")
    H = field.half_size
    if window is None:
        ax.set_xlim(-H, H)
        ax.set_ylim(-H, H)
    else:
        ax.set_xlim(window[0], window[1])
        ax.set_ylim(window[2], window[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title or f"field seed {field.seed}: top view")


def _draw_side(ax, field: Field, path, target, band: float = 10.0, title=None):
    from matplotlib.patches import Circle, Rectangle

    s = np.asarray(field.start, float)
    tgt = np.asarray(target, float)
    u = tgt[:2] - s[:2]
    u = u / max(np.linalg.norm(u), 1e-9)
    n = np.array([-u[1], u[0]])
    length = float(np.linalg.norm(tgt[:2] - s[:2]))

    def proj(x, y):
        q = np.array([x, y]) - s[:2]
        return float(q @ u), float(q @ n)

    for b in field.blocks:
        a, lat = proj(b.x, b.y)
        ext = max(b.sx, b.sy) / 2
        if abs(lat) < band + ext and -10 < a < length + 10:
            ax.add_patch(Rectangle((a - ext, 0), 2 * ext, b.sz, fc="#b07050", ec="k", lw=0.3, alpha=0.6))
    for t, c in zip(field.trunks, field.crowns, strict=True):
        a, lat = proj(t.x, t.y)
        if abs(lat) < band + c.radius and -10 < a < length + 10:
            ax.add_patch(Rectangle((a - t.radius, 0), 2 * t.radius, t.height, fc="#6b4a2b", lw=0))
            ax.add_patch(Circle((a, c.z), c.radius, fc="#4c9a4c", alpha=0.6, lw=0))
    P = np.asarray(path)
    along = (P[:, :2] - s[:2]) @ u
    ax.plot(along, P[:, 2], "-", c="tab:blue", lw=1.2)
    ax.plot(0, s[2], "k^", ms=7)
    ax.plot(length, tgt[2], "r*", ms=12)
    ax.set_xlim(-10, length + 10)
    ax.set_ylim(0, max(25.0, float(P[:, 2].max()) + 3))
    ax.set_xlabel("distance along start-target line (m)")
    ax.set_ylabel("altitude (m)")
    ax.set_title(title or f"side view (obstacles within {band:.0f} m of the line)")


def save_flight_pngs(field: Field, path, target, out_dir, prefix: str = "flight", title: str | None = None):
    """Write ``<prefix>_top.png`` (whole field and a zoom on the flight) and ``<prefix>_side.png``;
    returns the two file names."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from pathlib import Path

    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    P = np.asarray(path)
    fig, axes = plt.subplots(1, 2, figsize=(13, 6.5))
    try:
        _draw_topdown(axes[0], field, P, target, title=title)
        pts = np.vstack([P[:, :2], np.asarray(target)[None, :2]])
        lo, hi = pts.min(0) - 8, pts.max(0) + 8
        half = max(hi - lo) / 2
        mid = (lo + hi) / 2
        _draw_topdown(axes[1], field, P, target, title="zoom on the flight",
                      window=(mid[0] - half, mid[0] + half, mid[1] - half, mid[1] + half))
        fig.tight_layout()
        top = out / f"{prefix}_top.png"
        fig.savefig(top, dpi=90)
    finally:
        plt.close(fig)
    fig, ax = plt.subplots(figsize=(10, 4))
    try:
        _draw_side(ax, field, P, target)
        fig.tight_layout()
        side = out / f"{prefix}_side.png"
        fig.savefig(side, dpi=90)
    finally:
        plt.close(fig)
    return str(top), str(side)


def topdown_image(field: Field, path=None, target=None, size: int = 256) -> np.ndarray:
    """Cheap RGB top-down raster (size x size, uint8) for ``render()``: shapes dark, path red."""
    H = field.half_size
    img = np.full((size, size, 3), 235, np.uint8)
    xs = (np.arange(size) + 0.5) / size * 2 * H - H
    X, Y = np.meshgrid(xs, xs[::-1])
    for b in field.blocks:
        img[(abs(X - b.x) <= b.sx / 2) & (abs(Y - b.y) <= b.sy / 2)] = (150, 100, 70)
    for c in field.crowns:
        img[(X - c.x) ** 2 + (Y - c.y) ** 2 <= c.radius ** 2] = (70, 150, 70)

    def cell(q):
        col = np.clip(((np.asarray(q)[..., 0] + H) / (2 * H) * size).astype(int), 0, size - 1)
        row = np.clip(((H - np.asarray(q)[..., 1]) / (2 * H) * size).astype(int), 0, size - 1)
        return row, col

    if path is not None and len(path):
        r, c = cell(np.asarray(path))
        img[r, c] = (200, 30, 30)
    if target is not None:
        r, c = cell(np.asarray(target))
        img[max(r - 2, 0):r + 3, max(c - 2, 0):c + 3] = (220, 0, 0)
    return img
