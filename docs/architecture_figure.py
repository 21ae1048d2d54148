"""Draw docs/img/architecture.png: the layers and one decision's data flow, with the names the
registries hold when it is run.

    python docs/architecture_figure.py
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch  # noqa: E402

from cogmap import agents, inference  # noqa: E402
from cogmap.agent.encoder import available_encoders  # noqa: E402
from cogmap.envs.layouts import LAYOUTS  # noqa: E402
from cogmap.planning import efe  # noqa: E402
from cogmap.planning.planners import available_planners  # noqa: E402
from cogmap.plots import save_figure
from cogmap.study import studies  # noqa: E402

OUT = Path(__file__).resolve().parent / "img" / "architecture.png"
LAYER = {"cogmap (agent layer)": "#fde2c8", "envs": "#d8ecd3", "planning": "#d6e4f5", "inference": "#e6dcf2",
         "genmodel": "#f2f2d0"}


def _box(ax, x, y, w, h, title, body, color):
    ax.add_patch(FancyBboxPatch((x, y), w, h, boxstyle="round,pad=0.02,rounding_size=0.08", fc=color, ec="#444",
                                lw=1.0))
    ax.text(x + w / 2, y + h - 0.13, title, ha="center", va="top", fontsize=9.5, weight="bold")
    ax.text(x + w / 2, y + h - 0.42, body, ha="center", va="top", fontsize=7.6, linespacing=1.3, wrap=True)


def _arrow(ax, a, b, text="", rad=0.0):
    ax.add_patch(FancyArrowPatch(a, b, arrowstyle="-|>", mutation_scale=12, lw=1.2, color="#333",
                                 connectionstyle=f"arc3,rad={rad}"))
    if text:
        ax.text((a[0] + b[0]) / 2, (a[1] + b[1]) / 2 + 0.1, text, ha="center", va="bottom", fontsize=7.4,
                style="italic", color="#333")


def _names(xs, per_line=4) -> str:
    xs = list(xs)
    return "\n".join(", ".join(xs[i:i + per_line]) for i in range(0, len(xs), per_line))


def main() -> None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(13.5, 6.2), gridspec_kw={"width_ratios": [1, 1.55]})
    for ax in (left, right):
        ax.set_xlim(-0.3, 10)
        ax.set_ylim(0, 10)
        ax.axis("off")

    # the layers: the agent layer imports the libraries; inference, planning and envs import only
    # genmodel (tests/test_module_paths.py checks both, and that there is no import cycle)
    left.set_title("Layers: each imports only what is below it; no cycles", fontsize=10.5)
    _box(left, 0.3, 7.7, 9.4, 2.0, "cogmap (agent layer)", "agents: " + ", ".join(agents.agents())
         + "\nstudies: " + str(len(studies())) + " registered\nCLI, run directories, checkpoints",
         LAYER["cogmap (agent layer)"])
    libs = [("inference", "schemes:\n" + _names(inference.available(), 2)),
            ("planning", "planners: " + ", ".join(available_planners()) + "\nEFE terms: " + str(len(efe.ALL_TERMS))
             + " built in\nA*, hybrid A*, MI"),
            ("envs", f"rooms: {len(LAYOUTS)} factories\nLiDAR mazes, drone field\nGymnasium worlds")]
    for i, (name, body) in enumerate(libs):
        x = 0.3 + i * 3.2
        _box(left, x, 3.6, 3.0, 3.0, name, body, LAYER[name])
        _arrow(left, (x + 1.5, 7.7), (x + 1.5, 6.6))
        _arrow(left, (x + 1.5, 3.6), (x + 1.5, 2.5))
    _box(left, 0.3, 0.4, 9.4, 2.1, "genmodel", "specs, the compiled Model, dense and sparse A and B\n"
         "contracts (Protocols every registry checks), numerics", LAYER["genmodel"])

    # one decision, sensor reading to action
    right.set_title("One decision: from a sensor reading to an action", fontsize=10.5)
    w, h = 2.7, 1.75
    steps = [
        (0.2, 7.6, "world.step", "envs: panorama, LiDAR,\nodometry (Gymnasium\nobservation)", LAYER["envs"]),
        (3.6, 7.6, "encoder", "cogmap.agent: view ->\nobservation id\n(" + ", ".join(available_encoders()) + ")",
         LAYER["cogmap (agent layer)"]),
        (7.0, 7.6, "inference scheme", "inference.get(scheme)\n(model, prior, obs)\n-> posterior, F",
         LAYER["inference"]),
        (7.0, 4.2, "learning, growth", "inference.learning,\nreduction: Dirichlet counts,\nnew states (genmodel)",
         LAYER["inference"]),
        (3.6, 4.2, "planner", "planning.get_planner(name)\n(model, qs, objective,\nsettings) -> Plan",
         LAYER["planning"]),
        (0.2, 4.2, "EFE objective", "efe.objective({term: w})\nsum of registered terms\nper candidate",
         LAYER["planning"]),
        (3.6, 0.8, "action", "Plan.action -> waypoint\n(agent's info) ->\nworld.step(action)",
         LAYER["cogmap (agent layer)"]),
    ]
    for x, y, title, body, color in steps:
        _box(right, x, y, w, h, title, body, color)
    _arrow(right, (2.9, 8.45), (3.6, 8.45), "")
    _arrow(right, (6.3, 8.45), (7.0, 8.45), "")
    _arrow(right, (8.35, 7.6), (8.35, 5.95), "q(s)")
    _arrow(right, (7.0, 5.05), (6.3, 5.05), "model, q")
    _arrow(right, (2.9, 5.05), (3.6, 5.05), "G(ctx)")
    _arrow(right, (4.95, 4.2), (4.95, 2.55), "")
    right.plot([3.6, -0.1, -0.1], [1.65, 1.65, 8.1], color="#333", lw=1.2)
    _arrow(right, (-0.1, 8.1), (0.2, 8.1))
    right.text(1.6, 1.75, "next reading", ha="center", va="bottom", fontsize=7.4, style="italic", color="#333")
    right.text(5.0, 0.15, "agent: state = init(model, config, key); state, info = step(state, observation)",
               ha="center", fontsize=8.2, family="monospace")
    save_figure(fig, OUT, dpi=110)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
