"""Draw three procedural buildings side by side: ``python docs/buildings_figure.py`` writes
docs/img/envs/buildings.png (see docs/tutorial-aimapp.md, "Your own building")."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from cogmap.envs.buildings import building  # noqa: E402
from cogmap.envs.occupancy import layout_grid  # noqa: E402
from cogmap.envs.render import draw_layout  # noqa: E402

OUT = Path(__file__).resolve().parent / "img" / "envs" / "buildings.png"
SHOWN = (("office", 1), ("L", 3), ("U", 2))


def main() -> None:
    fig, axes = plt.subplots(1, 3, figsize=(18, 5.6), gridspec_kw={"width_ratios": [1.5, 1, 1]})
    for ax, (kind, seed) in zip(axes, SHOWN, strict=True):
        lay = building(seed, kind)
        area = layout_grid(lay).free_area(lay.starts[0][:2])
        draw_layout(lay, ax=ax, title=f'make_layout("building", seed={seed}, kind="{kind}"): {area:.0f} m²')
    fig.tight_layout()
    fig.savefig(OUT, dpi=80)
    print(OUT)


if __name__ == "__main__":
    main()
