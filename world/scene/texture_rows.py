"""Textures whose rows are whole multiples of 4 bytes, as PyBullet's renderers read them.

The renderers load a mesh's texture PNG as 3-byte RGB texels and hand the rows to OpenGL
with its default unpack alignment of 4 bytes: a row of W texels is read as if it took
``ceil(3 W / 4) * 4`` bytes. Where 3 W is not a multiple of 4 the image comes out sheared,
and its last rows are read from past the end of the loaded image: memory whose contents
differ from one process to the next. The town's 190 x 190 junction asphalt did that, and
the pixels along the junctions' edges (their texture coordinates 0 and 1) took a different
colour in every process: the camera's lane finder read a different line near the end of
``town_left_turn`` and the run's trajectory differed, run to run and machine to machine.

`aligned_texture` widens such a texture to the next multiple of 4 texels by repeating its
last column, and scales the texture coordinates' u so that every texel keeps its place on
the mesh (u in [0, 1], the meshes' way here); a mesh whose u runs outside [0, 1] (a texture
tiled across) is resampled to the aligned width instead, which keeps the tiling.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

ROW_ALIGNMENT = 4  # [bytes] OpenGL's default GL_UNPACK_ALIGNMENT
TEXEL_BYTES = 3  # RGB


def aligned_width(width: int) -> int:
    """The least width >= `width` [texels] whose RGB rows are a multiple of 4 bytes."""
    return -(-width // ROW_ALIGNMENT) * ROW_ALIGNMENT


def aligned_texture(texture: NDArray[np.uint8], uvs: NDArray[np.float64]
                    ) -> tuple[NDArray[np.uint8], NDArray[np.float64]]:
    """(texture (H, W', 3), uvs (N, 2)) drawing what `texture` (H, W, 3) and `uvs` draw,
    W' = `aligned_width(W)`; the inputs themselves when W is aligned already."""
    height, width = texture.shape[:2]
    wide = aligned_width(width)
    if wide == width:
        return texture, uvs
    u = uvs[:, 0]
    if len(u) and (u.min() < 0.0 or u.max() > 1.0):
        resampled = cv2.resize(texture, (wide, height), interpolation=cv2.INTER_LINEAR)
        return np.ascontiguousarray(resampled, dtype=np.uint8), uvs
    padded = np.concatenate([texture, np.repeat(texture[:, -1:], wide - width, axis=1)], axis=1)
    scaled = uvs.copy()
    scaled[:, 0] *= width / wide
    return padded, scaled
