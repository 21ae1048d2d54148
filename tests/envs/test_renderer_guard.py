"""The camera never hangs pybullet's TinyRenderer: no mesh vertex may lie in the camera's own plane
(the plane through the eye across the view), whether the eye sits exactly in a box face's plane or a
hair off it."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

pytest.importorskip("pybullet")

SCRIPT = textwrap.dedent("""
    import time
    from cogmap.envs.geometry import Box
    from cogmap.envs.layouts import Layout
    from cogmap.envs.world import PyBulletScene
    # a box with half-extents (0.35, 0.075, 1.0) at (0.35, 4.075, 1.0): its +y face is the plane y = 4.15
    box = Box("shelf", 0.35, 4.075, 0.7, 0.15, height=2.0)
    scene = PyBulletScene(Layout("guard", (0.0, 0.0, 22.0, 8.0), (box,), ((21.0, 4.15, 0.0),)), textured=False)
    t = time.perf_counter()
    image = scene.view((21.0, 4.15), 0.35, -1.5707963267948966, 64, 64, 90.0)  # eye in that plane, looking -y
    print(image.shape, time.perf_counter() - t)
""")


def test_camera_in_the_plane_of_a_box_face_renders():
    # without the guard this call never returns (pybullet cannot be interrupted from Python),
    # so it runs in a child process with a time limit
    done = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    shape, seconds = done.stdout.split(")")[0] + ")", float(done.stdout.split(")")[1])
    assert shape == "(64, 64, 3)" and seconds < 1.0


SCRIPT_NEAR = textwrap.dedent("""
    import sys, time
    from cogmap.envs.geometry import Box
    from cogmap.envs.layouts import Layout
    from cogmap.envs.world import PyBulletScene
    # a table whose south corners lie on y = -0.4, 25 m east of the eye; the eye is 0.29 um south of
    # that line (the old sub-micron offset), looking north: the corners are a hair in front of the
    # camera's plane (seen in building:office:1001, seed 1, decision 5)
    box = Box("table", 27.6, 0.0, 1.4, 0.8, height=0.75)
    scene = PyBulletScene(Layout("guard2", (0.0, -2.0, 33.0, 8.0), (box,), ((2.0, 0.0, 0.0),)),
                          textured=sys.argv[1] == "1")
    t = time.perf_counter()
    image = scene.view((2.126923788646684, -0.39999999999999947), 0.35, -4.71238898038469, 64, 64, 90.0)
    print(image.shape, time.perf_counter() - t)
""")


@pytest.mark.parametrize("textured", ["0", "1"])
def test_camera_a_hair_from_a_vertex_plane_renders(textured):
    # without the vertex guard this call never returns (also in the textured scene the sims use)
    done = subprocess.run([sys.executable, "-c", SCRIPT_NEAR, textured], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    shape, seconds = done.stdout.split(")")[0] + ")", float(done.stdout.split(")")[1])
    assert shape == "(64, 64, 3)" and seconds < 1.0


def test_guard_knows_where_every_vertex_is_also_after_a_move():
    from cogmap.envs.geometry import Box, Cylinder
    from cogmap.envs.layouts import Layout
    from cogmap.envs.world import PyBulletScene

    box = Box("b", 1.0, 2.0, 2.0, 1.0, height=1.0, yaw=np.pi / 2)
    can = Cylinder("c", 5.0, 5.0, 0.5, height=1.0)
    scene = PyBulletScene(Layout("v", (0.0, 0.0, 10.0, 10.0), (box, can), ((8.0, 8.0, 0.0),)), textured=False)
    try:
        xy = scene.vertex_xy()
        # a box turned by 90 degrees: corners at x 1 -+ 0.5, y 2 -+ 1; the cylinder's rim at radius 0.5
        corners = {(round(x, 6), round(y, 6)) for x, y in xy[4:8]}
        assert corners == {(0.5, 1.0), (1.5, 1.0), (1.5, 3.0), (0.5, 3.0)}
        np.testing.assert_allclose(np.hypot(*(xy[8:] - [5.0, 5.0]).T), 0.5)
        assert len(xy) == 4 + 4 + 12  # floor corners first
        scene.move_body("b", 3.0, 3.0, 0.0)
        moved = {(round(x, 6), round(y, 6)) for x, y in scene.vertex_xy()[4:8]}
        assert moved == {(2.0, 2.5), (4.0, 2.5), (4.0, 3.5), (2.0, 3.5)}
    finally:
        scene.close()
