"""The camera never hangs pybullet's TinyRenderer: an eye exactly in the plane of a box face."""

from __future__ import annotations

import subprocess
import sys
import textwrap

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
