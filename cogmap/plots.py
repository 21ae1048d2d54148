"""PNG figures of a run: the cognitive map over the floor plan, and the coverage curve."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (figures written to files, no display needed).

    Returns
    -------
    module
        ``matplotlib.pyplot``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: Path, dpi: int = 110) -> None:
    """Lay out ``fig``, write it as a PNG to ``path`` (its folder created if missing) and close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : pathlib.Path
        PNG file to write.
    dpi : int, optional
        Resolution, default 110.
    """
    import matplotlib.pyplot as plt

    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def map_over_floorplan(path: Path, sim, agent, ep, title: str | None = None) -> Path:
    """Floor plan, true path (grey), believed nodes coloured by observation, edges by belief.

    Parameters
    ----------
    path : pathlib.Path
        PNG file to write.
    sim : NavSim
        The simulator after the run (its ``layout`` and true ``path``).
    agent : AIMAPPAgent
        The agent after the run; its states are drawn at ``agent.poses`` with edges of
        transition probability >= 0.2 (line width grows with the probability), visited states
        coloured by their most likely observation. Nothing is drawn if it has no model yet.
    ep : Episode
        The run's record (final coverage and distance go in the title).
    title : str, optional
        Figure title; by default the layout name, number of states, coverage and distance.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    from cogmap.envs.render import draw_layout
    from cogmap.genmodel.graph import to_graph

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 8))
    draw_layout(sim.layout, path=np.asarray(sim.path), ax=ax, show_starts=False)
    if agent.model is not None:
        g = to_graph(agent.model, min_prob=0.2)
        poses = agent.poses
        for a, b, data in g.edges(data=True):
            ax.plot(*poses[[a, b]].T, color="tab:blue", lw=0.4 + 2.0 * data["prob"], alpha=0.6, zorder=4)
        visited = agent.visited()
        obs = agent.model.A[0].most_likely()
        ax.scatter(*poses[~visited].T, s=18, facecolors="white", edgecolors="tab:blue", zorder=5,
                   label="predicted (unvisited) states")
        ax.scatter(*poses[visited].T, s=34, c=obs[visited], cmap="tab20", edgecolors="k", lw=0.5, zorder=6,
                   label="visited states (colour = observation)")
        ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    cov = ep.coverage[-1] if ep.coverage else 0.0
    ax.set_title(title or f"{sim.layout.name}: {agent.num_states} states, coverage {cov:.0%}, "
                 f"{ep.distance[-1] if ep.distance else 0:.0f} m travelled")
    save_figure(fig, path, dpi=110)
    return Path(path)


def coverage_curve(path: Path, ep, label: str = "AIMAPP") -> Path:
    """LiDAR coverage (%) against distance travelled (m).

    Parameters
    ----------
    path : pathlib.Path
        PNG file to write.
    ep : Episode
        The run's record (``distance`` in metres and ``coverage`` in [0, 1], per step).
    label : str
        Legend label of the curve.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(ep.distance, np.asarray(ep.coverage) * 100, lw=2, label=label)
    ax.set_xlabel("distance travelled (m)")
    ax.set_ylabel("LiDAR coverage of free area (%)")
    ax.set_ylim(0, 101)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right")
    save_figure(fig, path, dpi=110)
    return Path(path)
