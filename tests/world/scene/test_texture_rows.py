"""Textures widened to whole 4-byte RGB rows (`world.scene.texture_rows`): every texel keeps
its place on the mesh; a frame of the town renders the same in every process."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from world.scene.texture_rows import aligned_texture, aligned_width


@pytest.mark.parametrize(("width", "aligned"), [(1, 4), (4, 4), (5, 8), (190, 192), (280, 280)])
def test_aligned_width_is_the_next_multiple_of_four(width: int, aligned: int) -> None:
    assert aligned_width(width) == aligned
    assert aligned_width(width) * 3 % 4 == 0


def _texel(texture: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The texel a (u, v) in [0, 1) falls in (nearest sampling)."""
    h, w = texture.shape[:2]
    texels: np.ndarray = texture[(v * h).astype(int), (u * w).astype(int)]
    return texels


@given(width=st.integers(1, 40), height=st.integers(1, 6), seed=st.integers(0, 2**16))
def test_padding_keeps_every_texel_where_the_mesh_shows_it(width: int, height: int,
                                                           seed: int) -> None:
    rng = np.random.default_rng(seed)
    texture = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
    uvs = rng.random((64, 2)) * 0.999
    wide, scaled = aligned_texture(texture, uvs)
    assert wide.shape == (height, aligned_width(width), 3)
    assert wide.flags.c_contiguous
    np.testing.assert_array_equal(scaled[:, 1], uvs[:, 1])
    np.testing.assert_array_equal(_texel(wide, scaled[:, 0], scaled[:, 1]),
                                  _texel(texture, uvs[:, 0], uvs[:, 1]))


def test_an_aligned_texture_is_left_as_it_is() -> None:
    texture = np.zeros((3, 8, 3), np.uint8)
    uvs = np.array([[0.0, 0.0], [1.0, 1.0]])
    out, out_uvs = aligned_texture(texture, uvs)
    assert out is texture and out_uvs is uvs


def test_a_tiled_texture_is_resampled_and_its_coordinates_kept() -> None:
    texture = np.full((2, 6, 3), 7, np.uint8)
    uvs = np.array([[0.0, 0.0], [3.5, 1.0]])  # tiled three and a half times across
    out, out_uvs = aligned_texture(texture, uvs)
    assert out.shape == (2, 8, 3) and (out == 7).all()
    assert out_uvs is uvs


RENDER = """
import hashlib, math
import numpy as np
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile, sensor_setup
from world.world import World
scenario = load_scenario("town_left_turn")
world = World(scenario.world, sensor_setup(Profile.DEFAULT, scenario.world.sensors.lidar),
              lidar=False)
camera = world.rig.sensor("front").camera
yaw = 0.637  # [rad] turning left in the junction: the asphalt's edges cross the view
c, s = math.cos(yaw), math.sin(yaw)
rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
frame = camera.render(0.0, np.array([87.59, 91.41, 0.0]), rotation)
print("frame", world.renderer.name, hashlib.sha256(frame.rgb.tobytes()).hexdigest())
world.close()
"""


@pytest.mark.slow
def test_a_town_frame_is_the_same_whatever_the_heap_held() -> None:
    """Two processes whose fresh heap memory is filled with different bytes
    (``MALLOC_PERTURB_``) draw the same frame: no renderer reads memory it did not write
    (the unaligned junction texture did, and each process drew its edges differently)."""
    out = []
    for perturb in ("85", "170"):
        run = subprocess.run([sys.executable, "-c", RENDER], check=False, capture_output=True,
                             text=True, timeout=300,
                             env={**os.environ, "MALLOC_PERTURB_": perturb})
        assert run.returncode == 0, run.stderr[-2000:]
        out.append(next(line.split()[1:] for line in run.stdout.splitlines()
                        if line.startswith("frame ")))
    assert out[0][0] == "EGL"  # the renderer that read past its texture
    assert out[0] == out[1]
