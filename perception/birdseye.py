"""Inverse perspective mapping: the front camera's view of the flat ground as a bird's-eye view.

Geometry (see `world.frames`): a ground point ``(x, y, 0)`` in the vehicle frame (x forward
from the car's centre, y left, z up, origin on the ground) is, in the camera's sensor frame,
``p_s = R^T ((x, y, 0) - t)`` with ``R, t`` the camera mount's rotation and position
(`SensorMount.rotation`, ``(mount.x, mount.y, mount.z)``). The pinhole model of `CameraInfo`
images ``p_s = (X, Y, Z)`` at ``u = cx - fx Y / X``, ``v = cy - fy Z / X`` (continuous pixel
coordinates, pixel i covering [i, i + 1)). Both steps are linear in homogeneous coordinates, so
the ground plane maps to the image by the 3 x 3 homography

    H = P R^T [[1, 0, -tx], [0, 1, -ty], [0, 0, -tz]],   P = [[cx, -fx, 0], [cy, 0, -fy], [1, 0, 0]]

with ``(u w, v w, w) = H (x, y, 1)`` and ``w = X`` the depth along the optical axis (> 0 in
front of the camera). Its inverse maps pixels back to the ground (valid below the horizon).

The bird's-eye view (BEV) is a metric grid on the ground: row 0 is the farthest band
(``x_max``), rows go towards the car; column 0 is the leftmost band (``y_max``), columns go
right. Pixel (col j, row i) is centred on ``x = x_max - (i + 0.5) res``, ``y = y_max - (j +
0.5) res``. The warp from a horizontal band of image rows (``crop_top`` .. ``crop_bottom``,
the part of the image the BEV can see) is precomputed once as an OpenCV fixed-point remap
table, so each frame costs one `cv2.remap`. OpenCV puts pixel centres at integer
coordinates: an OpenCV coordinate is the continuous coordinate minus 0.5.

No image is needed here except in `BirdseyeView.warp`; the geometry helpers are plain numpy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from world.frames import CameraInfo

FloatArray = NDArray[np.float64]

MIN_DEPTH = 1e-6  # [m] a point must be at least this far in front of the camera to image


@dataclass(frozen=True, slots=True)
class BevGrid:
    """The bird's-eye-view grid on the ground, in the vehicle frame."""

    x_min: float = 5.0  # [m] nearest forward distance from the car's centre (beyond the hood)
    x_max: float = 35.0  # [m] farthest forward distance
    y_min: float = -7.0  # [m] rightmost lateral position (left +)
    y_max: float = 7.0  # [m] leftmost lateral position
    resolution: float = 0.05  # [m/px] both axes

    @property
    def rows(self) -> int:
        """[px] along x (forward)."""
        return round((self.x_max - self.x_min) / self.resolution)

    @property
    def cols(self) -> int:
        """[px] along y (lateral)."""
        return round((self.y_max - self.y_min) / self.resolution)

    def row_to_x(self, row: ArrayLike) -> FloatArray:
        """[m] forward distance of the centre of BEV row(s) (integer index or fractional)."""
        return np.asarray(self.x_max - (np.asarray(row, dtype=np.float64) + 0.5)
                          * self.resolution)

    def col_to_y(self, col: ArrayLike) -> FloatArray:
        """[m] lateral position (left +) of the centre of BEV column(s)."""
        return np.asarray(self.y_max - (np.asarray(col, dtype=np.float64) + 0.5)
                          * self.resolution)

    def x_to_row(self, x: ArrayLike) -> FloatArray:
        """Fractional BEV row of forward distance(s) x [m] (inverse of `row_to_x`)."""
        return np.asarray((self.x_max - np.asarray(x, dtype=np.float64)) / self.resolution
                          - 0.5)

    def y_to_col(self, y: ArrayLike) -> FloatArray:
        """Fractional BEV column of lateral position(s) y [m] (inverse of `col_to_y`)."""
        return np.asarray((self.y_max - np.asarray(y, dtype=np.float64)) / self.resolution
                          - 0.5)


def ground_to_image_homography(camera: CameraInfo) -> FloatArray:
    """(3, 3) H with ``(u w, v w, w) = H (x, y, 1)``: vehicle-frame ground point (x, y) [m]
    to continuous pixel (u, v) [px]; ``w`` [m] is the point's depth along the optical axis."""
    m = camera.mount
    rot_t = m.rotation().T
    shift = np.array([[1.0, 0.0, -m.x], [0.0, 1.0, -m.y], [0.0, 0.0, -m.z]])
    project = np.array([[camera.cx, -camera.fx, 0.0], [camera.cy, 0.0, -camera.fy],
                        [1.0, 0.0, 0.0]])
    h: FloatArray = project @ rot_t @ shift
    return h


def _apply(h: FloatArray, points: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """(N, 2) points through homography h: (N, 2) results and (N,) homogeneous scales."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    hom = np.column_stack([pts, np.ones(len(pts))]) @ h.T
    w = hom[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        out = hom[:, :2] / w[:, None]
    return out, w


def ground_to_pixel(camera: CameraInfo, xy: ArrayLike) -> FloatArray:
    """(N, 2) continuous pixels (u, v) [px] of vehicle-frame ground points xy (N, 2) [m].

    Points behind the camera (depth <= `MIN_DEPTH`) give NaN."""
    uv, depth = _apply(ground_to_image_homography(camera), xy)
    uv[depth <= MIN_DEPTH] = np.nan
    return uv


def pixel_to_ground(camera: CameraInfo, uv: ArrayLike) -> FloatArray:
    """(N, 2) vehicle-frame ground points (x, y) [m] seen at continuous pixels uv (N, 2).

    Pixels on or above the horizon (whose ray does not reach the ground in front) give NaN."""
    h = ground_to_image_homography(camera)
    xy, _ = _apply(np.asarray(np.linalg.inv(h), dtype=np.float64), uv)
    _, depth = _apply(h, np.nan_to_num(xy))
    xy[~(depth > MIN_DEPTH)] = np.nan
    return xy


class BirdseyeView:
    """The precomputed warp of one camera's image onto one `BevGrid` (see module doc)."""

    def __init__(self, camera: CameraInfo, grid: BevGrid | None = None) -> None:
        self.camera = camera
        self.grid = grid if grid is not None else BevGrid()
        g = self.grid
        self.homography = ground_to_image_homography(camera)  # ground (x, y) -> pixel (u, v)
        cols, rows = np.meshgrid(np.arange(g.cols), np.arange(g.rows))
        ground = np.column_stack([g.col_to_y(cols.ravel()), g.row_to_x(rows.ravel())])
        uv, depth = _apply(self.homography, ground[:, ::-1])  # (x, y) order
        if not np.all(depth > MIN_DEPTH):
            raise ValueError("the bird's-eye grid reaches behind the camera's image plane")
        v = uv[:, 1]
        self.crop_top = max(0, math.floor(float(v.min())) - 1)  # [px] first image row used
        self.crop_bottom = min(camera.height, math.ceil(float(v.max())) + 1)  # [px] exclusive
        map_u = (uv[:, 0] - 0.5).reshape(g.rows, g.cols).astype(np.float32)
        map_v = (v - 0.5 - self.crop_top).reshape(g.rows, g.cols).astype(np.float32)
        self._map1, self._map2 = cv2.convertMaps(map_u, map_v, cv2.CV_16SC2)

    def crop(self, image: NDArray[np.uint8]) -> NDArray[np.uint8]:
        """The band of image rows the BEV is made of (a view, no copy)."""
        return image[self.crop_top:self.crop_bottom]

    def warp(self, cropped: NDArray[np.uint8]) -> NDArray[np.uint8]:
        """The BEV (grid.rows, grid.cols[, channels]) of an image band from `crop`, bilinear;
        grid cells outside the image are 0."""
        out = cv2.remap(cropped, self._map1, self._map2, cv2.INTER_LINEAR,
                        borderMode=cv2.BORDER_CONSTANT, borderValue=0)
        return np.asarray(out, dtype=np.uint8)
