"""Draw the room learned from a random walk (docs/plan-and-act.md, section 6): plain EM against
4 restarts with annealing, on the 5 x 5 room with 8 views and a 10,000-step walk of bench/fit.py.

    python docs/learned_room.py     # writes docs/img/learning/learned-room.png and .json

Learned states are labelled with the place where the smoothed posterior puts them most often
on the training walk (evaluation only: the learner never sees places). Every arrow is one move
(east, west, north, south) from a learned state to its most likely successor, drawn between
those places: grey where it is the true move, red where it is not.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from cogmap.genmodel.demo_models import ROOM_MOVES, aliased_room, room_model, room_walk
from cogmap.inference.exact import exact
from cogmap.inference.fit import fit, surprise_bits

OUT = Path(__file__).resolve().parent / "img" / "learning"
SIDE, VIEWS, STEPS = 5, 8, 10000




def place_of_states(model, obs, acts, places):
    """For each learned state, the true place it stands for most often on the walk (exact
    smoothing under the learned model)."""
    n = model.num_states[0]
    _, info = exact(model, [model.live_D(0)], obs, [(u,) for u in acts])
    gamma = np.array([q[0] for q in info.history])
    mass = np.zeros((n, n))  # (place, state)
    np.add.at(mass, places, gamma)
    return mass.argmax(axis=0)


def draw(ax, model, where, B_true, label, title):
    B = model.live_B(0)
    xy = np.array([(s % SIDE, s // SIDE) for s in range(SIDE * SIDE)], dtype=float)
    wrong = 0
    for j in range(B.shape[1]):
        for u in range(1, B.shape[2]):  # the moves; staying is not drawn
            src, dst = where[j], where[B[:, j, u].argmax()]
            ok = dst == B_true[:, src, u].argmax()
            wrong += not ok
            if src == dst:
                continue
            off = 0.08 * np.array(ROOM_MOVES[u])[::-1] * (1 if u % 2 else -1)
            ax.annotate("", xy=xy[dst] + off, xytext=xy[src] + off,
                        arrowprops=dict(arrowstyle="->", color="0.55" if ok else "red", lw=1.0 if ok else 1.8,
                                        shrinkA=9, shrinkB=9))
    for s in range(SIDE * SIDE):
        used = np.sum(where == s)
        ax.scatter(*xy[s], s=420, color="white" if used == 1 else "#f4c7c3", edgecolor="k", zorder=3)
        ax.text(*xy[s], str(label[s]), ha="center", va="center", fontsize=9, zorder=4)
    ax.set_title(title, fontsize=9)
    ax.set_aspect("equal")
    ax.axis("off")
    return wrong


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    A, B, label = aliased_room(SIDE, VIEWS, noise=0.05)
    n = SIDE * SIDE
    obs, acts, places = room_walk(A, B, STEPS, 0)
    held_obs, held_acts, _ = room_walk(A, B, 2000, 1)
    true_bits = surprise_bits(room_model(A, B), held_obs, held_acts)
    fig, axes = plt.subplots(1, 2, figsize=(9, 4.6))
    summary = {"true_bits": true_bits}
    fits = (("plain EM", {}), ("4 restarts, annealed", dict(restarts=4, anneal_iterations=40)))
    for ax, (name, kw) in zip(axes, fits, strict=True):
        model = room_model(A, B, conc=1 / n)
        res = fit(model, [(obs, acts)], learn_A=False, iterations=200, init_counts=1.0, seed=0, **kw)
        bits = surprise_bits(model, held_obs, held_acts)
        where = place_of_states(model, obs, acts, places)
        wrong = draw(ax, model, where, B, label, "")
        ax.set_title(f"{name}: F = {res.free_energy[-1]:.0f} nats, {bits:.3f} bits/step held out\n"
                     f"(true model {true_bits:.3f}); moves wrong: {wrong} of {4 * n}, "
                     f"places without a state: {n - len(set(where))}", fontsize=8.5)
        summary[name] = {"free_energy": res.free_energy[-1], "restart_free_energy": res.restart_free_energy,
                         "bits": bits, "wrong_moves": wrong, "places_without_state": n - len(set(where))}
    fig.suptitle("Room learned from a 10,000-step random walk. Numbers: each place's view; red: a wrong move;\n"
                 "pink: a place that no learned state, or more than one, stands for", fontsize=9.5)
    fig.tight_layout()
    OUT.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT / "learned-room.png", dpi=110)
    (OUT / "learned-room.json").write_text(json.dumps(summary, indent=1))
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
