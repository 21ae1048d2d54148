"""Top-down pictures of a maze, a trajectory and (optionally) LiDAR beams."""

from __future__ import annotations

import numpy as np

from .maze import Maze


def draw_maze(maze: Maze, ax, paths=(), pose=None, scan=None, particles=None, title: str | None = None):
    """Draw walls, labelled paths ``[(label, (K, >=2) array, colour)]``, an agent pose with its scan
    and particles ``(K, >=2)`` on a matplotlib axis."""
    from matplotlib.patches import Rectangle

    for cx, cy, sx, sy in maze.walls:
        ax.add_patch(Rectangle((cx - sx / 2, cy - sy / 2), sx, sy, fc="k", ec="none"))
    for label, path, colour in paths:
        p = np.asarray(path, float)
        ax.plot(p[:, 0], p[:, 1], "-", c=colour, lw=0.8, label=label)
    if particles is not None:
        q = np.asarray(particles, float)
        ax.scatter(q[:, 0], q[:, 1], s=6, c="tab:orange", zorder=6)
    if pose is not None:
        x, y, a = pose
        if scan is not None:
            n = len(scan)
            ang = a + 2 * np.pi * np.arange(n) / n
            for r, b in zip(scan, ang, strict=True):
                ax.plot([x, x + r * np.cos(b)], [y, y + r * np.sin(b)], "-", c="tab:green", lw=0.5)
        ax.plot(x, y, "o", c="tab:red", ms=4, zorder=7)
        ax.plot([x, x + 0.05 * maze.size * np.cos(a)], [y, y + 0.05 * maze.size * np.sin(a)], "r-", zorder=7)
    pad = 0.03 * maze.size
    ax.set_xlim(-pad, maze.size + pad)
    ax.set_ylim(-pad, maze.size + pad)
    ax.set_aspect("equal")
    if paths:
        ax.legend(loc="upper right", fontsize=7)
    ax.set_title(title if title is not None else f"maze {maze.seed} ({maze.complexity}, {maze.corridor})")
    return ax


def save_maze_png(maze: Maze, filename, paths=(), pose=None, scan=None, particles=None,
                  title: str | None = None, dpi: int = 110) -> str:
    """Render :func:`draw_maze` to a PNG file (matplotlib Agg); returns the file name."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 5))
    try:
        draw_maze(maze, ax, paths, pose, scan, particles, title)
        fig.tight_layout()
        fig.savefig(filename, dpi=dpi)
    finally:
        plt.close(fig)
    return str(filename)


def maze_image(maze: Maze, pose=None, path=None, resolution: int = 200) -> np.ndarray:
    """Cheap RGB raster (row 0 at the top is max y) of the walls, a path and the agent."""
    occ = maze.occupancy(resolution)  # [ix, iy]
    img = np.where(occ[..., None], 30, 240).astype(np.uint8).repeat(3, axis=2)

    def _px(xy):
        return np.clip((np.asarray(xy, float)[..., :2] / maze.size * resolution).astype(int), 0, resolution - 1)

    if path is not None and len(path):
        ij = _px(path)
        img[ij[:, 0], ij[:, 1]] = (200, 40, 40)
    if pose is not None:
        i, j = _px(pose)
        img[max(i - 2, 0):i + 3, max(j - 2, 0):j + 3] = (220, 0, 0)
    return np.ascontiguousarray(np.transpose(img, (1, 0, 2))[::-1])


def save_plans_png(maze: Maze, paths: dict, filename, radius: float, n: int = 4) -> None:
    """Planned (dashed) and executed (solid) paths of the first ``n`` pairs, learned model beside the
    true simulator (paper Figure 6a-b).

    Parameters
    ----------
    maze : Maze
        The maze drawn underneath.
    paths : dict
        Model name -> ``[(pair, Plan, executed (n, 3), goal (3,))]`` (``extra["paths"]`` of
        :func:`cogmap.dvbf.navigate.navigate_pairs`); only ``learned`` and ``true`` are drawn.
    filename : path
        PNG file to write.
    radius : float
        Success radius drawn around each goal (maze units).
    n : int
        Pairs drawn per panel.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    names = [k for k in ("learned", "true") if k in paths]  # learned_mean is in pairs.csv, not drawn
    fig, axes = plt.subplots(1, len(names), figsize=(5 * len(names), 5), squeeze=False)
    colours = plt.get_cmap("tab10").colors
    try:
        for ax, name in zip(axes[0], names, strict=True):
            where = "the learned model" if name == "learned" else "the true simulator"
            draw_maze(maze, ax, title=f"maze {maze.seed}: planned in {where} (dashed), executed (solid)")
            ax.title.set_fontsize(8)
            for k, ((i, j), plan, executed, goal) in enumerate(paths[name][:n]):
                c = colours[k % len(colours)]
                if plan.found:
                    ax.plot(plan.poses[:, 0], plan.poses[:, 1], "--", c=c, lw=1.2)
                ax.plot(executed[:, 0], executed[:, 1], "-", c=c, lw=0.8, alpha=0.8, label=f"{i} -> {j}")
                ax.plot(*executed[0, :2], "o", c=c, ms=4)
                ax.add_patch(plt.Circle(goal[:2], radius, fc="none", ec=c, lw=0.8))
            ax.legend(loc="upper right", fontsize=7)
        fig.tight_layout()
        fig.savefig(filename, dpi=110)
    finally:
        plt.close(fig)


def save_error_png(err, err_pi, filename, label: str = "online") -> None:
    """The localisation error of a SLAM run and of path integration over the steps, as a PNG.

    Parameters
    ----------
    err, err_pi : numpy.ndarray
        ``(T,)`` errors of the SLAM estimate and of path integration, maze units.
    filename : path
        PNG to write.
    label : str, optional
        ``"online"`` or ``"offline"`` (the SLAM's legend entry).
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    try:
        ax.plot(err, label=f"DVBF-LM {label} SLAM", c="tab:blue")
        ax.plot(err_pi, label="path integration", c="tab:red")
        ax.set_xlabel("step")
        ax.set_ylabel("localisation error (maze side = 1)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(filename, dpi=110)
    finally:
        plt.close(fig)


def save_ratio_png(results, maze: Maze, filename) -> None:
    """Exploration ratio (and, where recorded, information gain) over the steps of each method, as a PNG.

    Parameters
    ----------
    results : dict
        Method name -> :class:`~cogmap.envs.maze_episode.ExploreResult`.
    maze : Maze
        The maze explored (its tile count labels the axis).
    filename : path
        PNG to write.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    has_info = any(r.info_curve for r in results.values())
    fig, axes = plt.subplots(1, 2 if has_info else 1, figsize=(10 if has_info else 5.5, 3.6), squeeze=False)
    colours = {"mi": "tab:blue", "random": "tab:red", "frontier": "tab:green"}
    try:
        for m, r in results.items():
            c = np.array(r.ratio_curve)
            axes[0, 0].plot(c[:, 0], c[:, 1], c=colours.get(m, "k"), label=m)
            if has_info and r.info_curve:
                i = np.array(r.info_curve)
                axes[0, 1].plot(i[:, 0], i[:, 1], c=colours.get(m, "k"), label=m)
        axes[0, 0].set_xlabel("step")
        axes[0, 0].set_ylabel(f"exploration ratio ({maze.tiles} x {maze.tiles} tiles)")
        axes[0, 0].set_ylim(0, 1.02)
        axes[0, 0].legend()
        if has_info:
            axes[0, 1].set_xlabel("step")
            axes[0, 1].set_ylabel("information gain KL(q(M) || p(M)) (nats)")
            axes[0, 1].legend()
        fig.tight_layout()
        fig.savefig(filename, dpi=110)
    finally:
        plt.close(fig)
