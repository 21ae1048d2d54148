import matplotlib
import numpy as np
import pytest

from cogmap.envs.layouts import LAYOUTS, make_layout
from cogmap.envs.occupancy import layout_grid
from cogmap.envs.render import demo_walk, grid_image, save_layout_png

matplotlib.use("Agg")


@pytest.mark.parametrize("name", sorted(LAYOUTS))
def test_png_per_layout(tmp_path, name):
    import matplotlib.image as mpimg

    lay = make_layout(name)
    path, graph = demo_walk(lay, 30)
    assert graph.number_of_nodes() >= 2 and all("pos" in d for _, d in graph.nodes(data=True))
    out = save_layout_png(lay, tmp_path / f"{name}.png", path=path, graph=graph,
                          grid=layout_grid(lay), robot=(*path[-1], 0.0))
    img = mpimg.imread(out)
    assert img.shape[0] > 200 and img.shape[1] > 400
    assert img[..., :3].std() > 0.05  # not a blank canvas


def test_grid_image_marks_robot():
    lay = make_layout("bedroom")
    g = layout_grid(lay)
    img = grid_image(g, robot_xy=np.array([2.0, 1.2]))
    assert img.shape == (*g.shape, 3)
    assert (img == [220, 0, 0]).all(-1).sum() == 49
