"""Top-down pictures of a layout, a robot path and an optional graph overlay."""

from __future__ import annotations

import numpy as np

from .geometry import Box, Cylinder
from .layouts import Layout


def _patches(layout: Layout):
    from matplotlib.patches import Circle, Polygon

    out = []
    for s in layout.shapes:
        if isinstance(s, Cylinder):
            out.append(Circle((s.x, s.y), s.radius, fc=s.color, ec="k", lw=0.4))
        elif isinstance(s, Box):
            c, n = np.cos(s.yaw), np.sin(s.yaw)
            corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [s.sx / 2, s.sy / 2]
            rot = corners @ np.array([[c, n], [-n, c]]) + [s.x, s.y]
            out.append(Polygon(rot, closed=True, fc=s.color, ec="k", lw=0.4))
    return out


def draw_layout(layout: Layout, path=None, graph=None, grid=None, robot=None, ax=None,
                title: str | None = None, show_starts: bool = True):
    """Draw on a matplotlib axis: occupancy (optional), shapes, starts, path, graph, robot.

    path: (K, 2) or (K, 3) array of poses; graph: networkx graph whose nodes carry `pos`;
    robot: (x, y, yaw) drawn as a disc with a heading tick.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(8, 8))
    xmin, ymin, xmax, ymax = layout.bounds
    ax.add_patch(plt.Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fc="#f4f1ea", ec="none"))
    if grid is not None:
        img = np.where(grid.occupied, 0.25, 1.0)
        ny, nx = grid.shape
        ax.imshow(img, origin="lower", cmap="gray", vmin=0, vmax=1, alpha=0.35,
                  extent=(grid.origin[0], grid.origin[0] + nx * grid.resolution,
                          grid.origin[1], grid.origin[1] + ny * grid.resolution))
    for p in _patches(layout):
        ax.add_patch(p)
    if show_starts:
        for x, y, _ in layout.starts:
            ax.plot(x, y, "g^", ms=6)
    if graph is not None:
        pos = {n: d["pos"] for n, d in graph.nodes(data=True) if "pos" in d}
        for u, v in graph.edges():
            if u in pos and v in pos:
                ax.plot([pos[u][0], pos[v][0]], [pos[u][1], pos[v][1]], "-", c="tab:purple",
                        lw=1.0, alpha=0.8)
        if pos:
            xy = np.array(list(pos.values()), float)
            ax.scatter(xy[:, 0], xy[:, 1], s=25, c="tab:purple", zorder=5)
    if path is not None and len(path):
        p = np.asarray(path, float)
        ax.plot(p[:, 0], p[:, 1], "-", c="tab:red", lw=1.5, zorder=6)
    if robot is not None:
        x, y, yaw = robot
        ax.add_patch(plt.Circle((x, y), 0.22, fc="tab:red", ec="k", zorder=7))
        ax.plot([x, x + 0.4 * np.cos(yaw)], [y, y + 0.4 * np.sin(yaw)], "k-", zorder=8)
    ax.set_xlim(xmin - 0.3, xmax + 0.3)
    ax.set_ylim(ymin - 0.3, ymax + 0.3)
    ax.set_aspect("equal")
    ax.set_title(title if title is not None else layout.name)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    return ax


def save_layout_png(layout: Layout, filename, path=None, graph=None, grid=None, robot=None,
                    title: str | None = None, dpi: int = 110) -> str:
    """Render a layout top-down to a PNG file (matplotlib Agg); returns the file name."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    xmin, ymin, xmax, ymax = layout.bounds
    aspect = (ymax - ymin) / max(xmax - xmin, 1e-6)
    fig, ax = plt.subplots(figsize=(8, max(3.0, 8 * aspect) + 0.6))
    try:
        draw_layout(layout, path, graph, grid, robot, ax=ax, title=title)
        fig.tight_layout()
        fig.savefig(filename, dpi=dpi)
    finally:
        plt.close(fig)
    return str(filename)


def grid_image(grid, robot_xy=None, path=None) -> np.ndarray:
    """Cheap RGB top-down image of an occupancy grid (row 0 at the top is max y)."""
    img = np.where(grid.occupied[..., None], 40, 235).astype(np.uint8).repeat(3, axis=2)
    if path is not None and len(path):
        rc = grid.world_to_cell(np.asarray(path, float)[:, :2])
        ok = grid.in_bounds(rc)
        img[rc[ok, 0], rc[ok, 1]] = (200, 30, 30)
    if robot_xy is not None:
        r, c = grid.world_to_cell(robot_xy[:2])
        img[max(r - 3, 0):r + 4, max(c - 3, 0):c + 4] = (220, 0, 0)
    return np.ascontiguousarray(img[::-1])


def demo_walk(layout: Layout, n_steps: int = 60, seed: int = 0, spacing: float = 1.0):
    """A seeded random walk (no pybullet) and a pose graph over it, for illustrations.

    A node is added whenever the robot is more than `spacing` from every node; consecutive
    nearest nodes are joined by an edge.
    """
    import networkx as nx

    from .geometry import ShapeSet
    from .robot import ROBOT_RADIUS, straight_move

    rng = np.random.default_rng(seed)
    shapes = ShapeSet(layout.shapes)
    xy = np.array(layout.starts[0][:2], float)
    path, graph = [xy.copy()], nx.Graph()
    graph.add_node(0, pos=tuple(xy))
    nodes, last, heading = [xy.copy()], 0, 0
    for _ in range(n_steps):
        if rng.random() < 0.3:
            heading = (heading + int(rng.integers(-2, 3))) % 12
        a = 2 * np.pi * heading / 12
        end, dist, ok, _ = straight_move(shapes, ROBOT_RADIUS, xy,
                                         xy + np.array([np.cos(a), np.sin(a)]))
        if not ok:
            heading = (heading + 6) % 12
        if dist <= 0:
            continue
        xy = end
        path.append(xy.copy())
        d = np.hypot(*(np.array(nodes) - xy).T)
        if d.min() > spacing:
            graph.add_node(len(nodes), pos=tuple(xy))
            nodes.append(xy.copy())
            cur = len(nodes) - 1
        else:
            cur = int(np.argmin(d))
        if cur != last:
            graph.add_edge(last, cur)
        last = cur
    return np.array(path), graph


def main(argv=None) -> None:
    """Write one PNG per layout: `python -m cogmap.envs.render OUTDIR`."""
    import sys
    from pathlib import Path

    from .layouts import LAYOUTS, make_layout
    from .occupancy import layout_grid

    out = Path((argv or sys.argv[1:] or ["docs/img/envs"])[0])
    out.mkdir(parents=True, exist_ok=True)
    for name in LAYOUTS:
        lay = make_layout(name, 0)
        grid = layout_grid(lay)
        path, graph = demo_walk(lay, 80)
        area = grid.free_area(lay.starts[0][:2])
        paper = f", paper {lay.paper_area:g} m2" if lay.paper_area else ""
        save_layout_png(lay, out / f"{name}.png", path=path, graph=graph, grid=grid,
                        title=f"{name}: free area {area:.1f} m2{paper}")
        print(out / f"{name}.png")


if __name__ == "__main__":
    main()
