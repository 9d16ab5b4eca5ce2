"""Stop signs in a camera frame, by colour and shape, and their match with the map's signs.

`StopSignDetector.detect(frame)` takes one `CameraFrame`, (H, W, 3) RGB, and returns the stop
signs it sees as `SignDetection`s, nearest first: the plate's centre [m] in the vehicle frame
(x forward from the car's centre, y left, z up from the ground). Classical and stateless, one
frame at a time, OpenCV and numpy only: the plate's size is the standard one, not read from
the world model. `match_sign` pairs a detection with a sign of the HD map.

The sign: a regular octagon, flat on top, `STOP_PLATE_DIAMETER` across the flats, red with a
white border (`STOP_BORDER_FRACTION` of that width) and the white word STOP. The red field,
which the colour test finds, is `STOP_FIELD_WIDTH` across.

1. **Red mask** in OpenCV's 8-bit HSV (hue 0..179 in 2 deg units, S and V 0..255): hue <=
   ``hue_low_max`` or >= ``hue_high_min``, S >= ``min_saturation`` and V >= ``min_value``.
   The saturation floor cuts the plate close to its true outline (anti-aliased edge pixels
   fall below it), which the range estimate relies on; the narrow hue band leaves brick
   facades out; red cars pass and fail the shape tests. A morphological close
   (``close_kernel`` square) mends the one-pixel gaps that the letters or a pole drawn through
   a distant plate leave; then the external contours of the closed mask.

1b. **Split**: a plate in front of a facade of a red-brown in the hue band (a brick's
   jittered hue falls on either side of ``hue_low_max``) joins it in one blob, too large or
   of the wrong shape. A blob rejected so (too large, or failing the tests of step 2 with a
   saturated core and the red fill of a plate) is taken again within its box with only the
   pixels of saturation ``split_saturation`` and more: the plate's red stays, the facade's
   duller red goes; the parts are measured as in step 2 (their red fill against that
   stricter mask). A blob found whole is never split, so a plate seen alone is measured as
   before; nor one that fails for its colour (red over less than ``min_red_fill`` of it, as a
   speed-limit sign's ring around its white disc): a plate joined to a facade is all red.

2. **Per blob** (a contour and its filled inside, the "plate"):

   - size: the bounding box's smaller side >= ``min_size_px`` and larger side <=
     ``max_size_px``, the red field's width in pixels, fy `STOP_FIELD_WIDTH` / X, at
     ``max_range`` and at ``min_range``;
   - colour: a saturated core (a pixel with S >= ``core_saturation``, which the plate's red
     reaches and a lit brick wall does not) and red over at least ``min_red_fill`` of the
     plate (the letters are a small part of the field; a speed-limit sign's red ring encloses
     a white disc);
   - shape: box aspect (width / height) within ``aspect``; solidity (contour area / hull
     area) >= ``min_solidity``; extent (plate pixels / box pixels) within ``extent`` (an
     octagon fills `OCTAGON_AREA_FACTOR` = 2 (sqrt 2 - 1) = 0.83 of its box, a rectangle such
     as a car's back or a facade all of it); from ``polygon_min_px`` across, where corners are
     resolved, the convex hull's ``approxPolyDP`` (epsilon ``polygon_epsilon`` of its
     perimeter) has a vertex count within ``polygon_vertices``, and below that the hull's
     circularity 4 pi A / P^2 (an octagon 0.95, a square 0.79) reaches ``min_circularity``;
   - white inside: from ``white_min_px`` across, where the letters are resolved, pixels with
     S <= ``white_max_saturation`` and V >= ``min_value`` make at least ``min_white_fill`` of
     the plate; smaller, the letters blur into pink and are not asked for.

3. **Position**: the plate faces the traffic, about parallel to a forward camera's image
   plane, so its apparent size gives the depth. The red field's width comes from the plate's
   pixel count N, an unbiased area that averages over the whole outline (the contour's
   extremes lose a pixel per side): width_px = sqrt(N / `OCTAGON_AREA_FACTOR`). The depth
   along the optical axis is X = fy `STOP_FIELD_WIDTH` / width_px; the centroid (u, v) gives
   Y = -(u - cx) X / fx and Z = -(v - cy) X / fy in the camera frame, and the mount takes
   them to the vehicle frame; ``range`` is the horizontal distance from the car's centre. A
   plate seen at an angle a is foreshortened by cos a across, so its range comes out
   1 / sqrt(cos a) too long. A plate centre outside ``plate_height`` above the ground is not a
   sign: a red patch of a sign's apparent size but another true size sits at the wrong depth,
   underground or in the air.

4. **Confidence** in [0, 1]: a size factor, rising from 0.6 at ``min_size_px`` to 1 at
   ``polygon_min_px``, times the mean of a colour score (red fill / 0.85, at most 1), a shape
   score and a letters score (1 when seen, 0.5 when too small to tell). The shape score is
   the mean of 1 - |extent - `OCTAGON_AREA_FACTOR`| / 0.1 (at least 0), the solidity, and
   the outline's score: 1 for 8 vertices, else 0.6; below ``polygon_min_px``, (circularity
   - ``min_circularity``) / 0.1, at most 1.

`match_sign` (`SignDetection.match`, which the planner can reach) moves a detection into the
map frame with the ego's pose and takes the nearest map sign within ``tolerance`` across the
line of sight and ``tolerance + range_tolerance * range`` along it: the apparent size gives
the range to a few per cent (a pixel is much of a small plate's width), the bearing better.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from cv2.typing import MatLike
from numpy.typing import NDArray

from perception.messages import EgoState, SignDetection
from world.frames import CameraFrame, CameraInfo

STOP_PLATE_DIAMETER = 0.75  # [m] stop plate width across the flats (standard size)
STOP_BORDER_FRACTION = 0.04  # [-] white border width / width across the flats
STOP_FIELD_WIDTH = STOP_PLATE_DIAMETER * (1.0 - 2.0 * STOP_BORDER_FRACTION)  # [m] red field
OCTAGON_AREA_FACTOR = 2.0 * (math.sqrt(2.0) - 1.0)  # [-] regular octagon area / width^2
STOP = "stop"

UInt8Array = NDArray[np.uint8]


@dataclass(frozen=True, slots=True)
class StopSignParams:
    """Thresholds of `StopSignDetector`, by step of the module docstring."""

    # -- red mask, OpenCV 8-bit HSV: hue [2 deg units] 0..179, saturation and value 0..255
    hue_low_max: int = 6  # [2 deg] top of the low red band (below brick facades' hue)
    hue_high_min: int = 170  # [2 deg] bottom of the high red band (hue wraps at 180)
    min_saturation: int = 100  # [0..255] anti-aliased edge pixels fall below: a true outline
    min_value: int = 60  # [0..255] also the white letters' floor
    close_kernel: int = 3  # [px] square structuring element of the morphological close
    split_saturation: int = 170  # [0..255] a rejected blob is split again at this floor: a
    #   plate's red (about 235) standing against a dull red facade (a brick's about 120)
    # -- size, from the intrinsics
    min_range: float = 3.0  # [m] nearest plate looked for (sets the largest blob)
    max_range: float = 50.0  # [m] farthest plate looked for (sets the smallest blob)
    # -- colour
    core_saturation: int = 190  # [0..255] the plate's red reaches it, a lit brick wall not
    min_red_fill: float = 0.6  # [-] red pixels / plate pixels
    white_max_saturation: int = 80  # [0..255] the white letters
    white_min_px: float = 14.0  # [px] blob size from which the letters are asked for
    min_white_fill: float = 0.02  # [-] white pixels / plate pixels
    # -- shape
    aspect: tuple[float, float] = (0.75, 1.33)  # [-] box width / height
    min_solidity: float = 0.85  # [-] contour area / convex hull area
    extent: tuple[float, float] = (0.70, 0.92)  # [-] plate pixels / box pixels
    polygon_min_px: float = 20.0  # [px] blob size from which the octagon's corners are sought
    polygon_epsilon: float = 0.025  # [-] approxPolyDP tolerance / hull perimeter
    polygon_vertices: tuple[int, int] = (7, 9)  # [-] inclusive band of the hull's polygon
    min_circularity: float = 0.80  # [-] 4 pi A / P^2 of the hull (octagon 0.95, square 0.79)
    # -- position
    plate_height: tuple[float, float] = (1.0, 4.0)  # [m] plate centre above the ground


@dataclass(frozen=True, slots=True)
class BlobMeasure:
    """What `StopSignDetector` measured of one red blob (for tuning and diagnostics)."""

    box: tuple[int, int, int, int]  # [px] u0, v0, u1, v1 (exclusive)
    pixels: int  # [-] plate pixels (the filled outline)
    centroid: tuple[float, float]  # [px] (u, v) of the plate, pixel centres at i + 0.5
    width_px: float  # [px] the red field's width across the flats (from the area)
    core: int  # [0..255] highest saturation of its red pixels
    red_fill: float  # [-]
    white_fill: float  # [-]
    aspect: float  # [-] box width / height
    solidity: float  # [-]
    extent: float  # [-]
    circularity: float  # [-] of the convex hull
    vertices: int  # [-] of the hull's polygon approximation


class StopSignDetector:
    """Finds stop signs in the frames of one camera (see the module docstring)."""

    def __init__(self, camera: CameraInfo, params: StopSignParams | None = None) -> None:
        self.camera = camera
        self.params = params or StopSignParams()
        p = self.params
        self.min_size_px = camera.fy * STOP_FIELD_WIDTH / p.max_range  # [px]
        self.max_size_px = camera.fy * STOP_FIELD_WIDTH / p.min_range  # [px]
        self._kernel = np.ones((p.close_kernel, p.close_kernel), np.uint8)

    # -- the pipeline ------------------------------------------------------------------------

    def detect(self, frame: CameraFrame) -> tuple[SignDetection, ...]:
        """The stop signs in ``frame``, nearest first."""
        if frame.info != self.camera:
            raise ValueError(f"frame of camera {frame.info.name!r}, detector of "
                             f"{self.camera.name!r} (or different calibration)")
        found = []
        for blob in self.measure(frame.rgb):
            confidence = self.score(blob)
            if confidence <= 0.0:
                continue
            detection = self._locate(frame.t, blob, confidence)
            lo, hi = self.params.plate_height
            if lo <= detection.z <= hi:
                found.append(detection)
        return tuple(sorted(found, key=lambda d: d.range))

    def red_mask(self, hsv: UInt8Array) -> UInt8Array:
        """(H, W) 0/255: the pixels of stop-sign red."""
        p = self.params
        low = cv2.inRange(hsv, (0, p.min_saturation, p.min_value),
                          (p.hue_low_max, 255, 255))
        high = cv2.inRange(hsv, (p.hue_high_min, p.min_saturation, p.min_value),
                           (179, 255, 255))
        return np.asarray(cv2.bitwise_or(low, high), dtype=np.uint8)

    def measure(self, rgb: UInt8Array) -> list[BlobMeasure]:
        """Every red blob of a plausible size in an (H, W, 3) RGB image, measured; a blob
        too large, or of a plausible size but rejected with a saturated core, is split
        again at ``split_saturation`` and its parts measured too (step 1b: not one red over
        too little of it)."""
        p = self.params
        hsv = np.asarray(cv2.cvtColor(rgb, cv2.COLOR_RGB2HSV), dtype=np.uint8)
        mask = self.red_mask(hsv)
        blobs = []
        for contour, rect in self._contours(mask):
            if max(rect[2], rect[3]) <= self.max_size_px:
                blob = self._measure_blob(contour, hsv, mask, rect)
                blobs.append(blob)
                if blob.core < p.core_saturation or blob.red_fill < p.min_red_fill or \
                        self.score(blob) > 0.0:
                    continue
            blobs.extend(self._split(hsv, mask, rect))
        return blobs

    def _contours(self, mask: UInt8Array) -> list[tuple[MatLike, tuple[int, int, int, int]]]:
        """The external contours of the closed `mask` and their bounding boxes [px] (u0,
        v0, w, h), those whose box's smaller side reaches ``min_size_px``."""
        closed = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, self._kernel)
        contours, _ = cv2.findContours(closed, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
        out = []
        for contour in contours:
            u0, v0, w, h = cv2.boundingRect(contour)
            if min(w, h) >= self.min_size_px:
                out.append((contour, (u0, v0, w, h)))
        return out

    def _split(self, hsv: UInt8Array, mask: UInt8Array,
               rect: tuple[int, int, int, int]) -> list[BlobMeasure]:
        """The blobs of plausible size within box `rect` [px] of `mask` once its pixels
        below ``split_saturation`` are left out, measured on that stricter mask."""
        u0, v0, w, h = rect
        rows, cols = slice(v0, v0 + h), slice(u0, u0 + w)
        strict = np.zeros_like(mask)
        saturated = hsv[rows, cols, 1] >= self.params.split_saturation
        strict[rows, cols] = np.where(saturated, mask[rows, cols], 0)
        return [self._measure_blob(contour, hsv, strict, r)
                for contour, r in self._contours(strict) if max(r[2], r[3]) <= self.max_size_px]

    def _measure_blob(self, contour: MatLike, hsv: UInt8Array, mask: UInt8Array,
                      rect: tuple[int, int, int, int]) -> BlobMeasure:
        p = self.params
        u0, v0, w, h = rect
        plate = np.zeros((h, w), np.uint8)
        cv2.drawContours(plate, [contour - np.array([u0, v0], np.int32)], -1, 255, cv2.FILLED)
        inside = plate > 0
        n = int(inside.sum())
        roi = hsv[v0:v0 + h, u0:u0 + w]
        red = (mask[v0:v0 + h, u0:u0 + w] > 0) & inside
        white = (roi[..., 1] <= p.white_max_saturation) & (roi[..., 2] >= p.min_value) & inside
        vs, us = np.nonzero(inside)
        hull = cv2.convexHull(contour)
        hull_area = float(cv2.contourArea(hull))
        perimeter = float(cv2.arcLength(hull, True))
        poly = cv2.approxPolyDP(hull, p.polygon_epsilon * perimeter, True)
        return BlobMeasure(
            box=(u0, v0, u0 + w, v0 + h),
            pixels=n,
            centroid=(u0 + float(us.mean()) + 0.5, v0 + float(vs.mean()) + 0.5),
            width_px=math.sqrt(n / OCTAGON_AREA_FACTOR),
            core=int(roi[..., 1][red].max(initial=0)),
            red_fill=float(red.sum()) / n,
            white_fill=float(white.sum()) / n,
            aspect=w / h,
            solidity=float(cv2.contourArea(contour)) / hull_area if hull_area > 0 else 0.0,
            extent=n / (w * h),
            circularity=4.0 * math.pi * hull_area / perimeter**2 if perimeter > 0 else 0.0,
            vertices=len(poly),
        )

    def score(self, b: BlobMeasure) -> float:
        """The blob's confidence as a stop sign, 0 when a test fails (module docstring)."""
        p = self.params
        size = min(b.box[2] - b.box[0], b.box[3] - b.box[1])
        if not self._passes(b, size):
            return 0.0
        octagon = 1.0 - min(1.0, abs(b.extent - OCTAGON_AREA_FACTOR) / 0.1)
        if size >= p.polygon_min_px:
            outline = 1.0 if b.vertices == 8 else 0.6
        else:
            outline = min(1.0, (b.circularity - p.min_circularity) / 0.1)
        shape = (octagon + b.solidity + outline) / 3.0
        letters = 1.0 if b.white_fill >= p.min_white_fill else 0.5  # 0.5: too small to tell
        colour = min(1.0, b.red_fill / 0.85)
        span = max(1e-9, p.polygon_min_px - self.min_size_px)
        size_factor = 0.6 + 0.4 * min(1.0, max(0.0, (size - self.min_size_px) / span))
        return size_factor * (colour + shape + letters) / 3.0

    def _passes(self, b: BlobMeasure, size: int) -> bool:
        p = self.params
        checks = (
            b.core >= p.core_saturation,
            b.red_fill >= p.min_red_fill,
            p.aspect[0] <= b.aspect <= p.aspect[1],
            b.solidity >= p.min_solidity,
            p.extent[0] <= b.extent <= p.extent[1],
            (p.polygon_vertices[0] <= b.vertices <= p.polygon_vertices[1]
             if size >= p.polygon_min_px else b.circularity >= p.min_circularity),
            size < p.white_min_px or b.white_fill >= p.min_white_fill,
        )
        return all(checks)

    def _locate(self, t: float, b: BlobMeasure, confidence: float) -> SignDetection:
        """The plate's centre in the vehicle frame from its size and centroid."""
        cam = self.camera
        depth = cam.fy * STOP_FIELD_WIDTH / b.width_px  # [m] along the optical axis
        u, v = b.centroid
        sensor = np.array([[depth, -(u - cam.cx) * depth / cam.fx,
                            -(v - cam.cy) * depth / cam.fy]])
        x, y, z = (float(c) for c in cam.mount.to_vehicle(sensor)[0])
        return SignDetection(t=t, kind=STOP, x=x, y=y, z=z, range=math.hypot(x, y),
                             box=b.box, confidence=confidence)


def match_sign(detection: SignDetection, ego: EgoState,
               map_signs: Sequence[tuple[float, float, float]], tolerance: float = 5.0,
               range_tolerance: float = 0.15) -> float | None:
    """The station [m] of the map sign ``detection`` is, or None: `SignDetection.match`
    (which lives with the message so that the planner, which may import only
    `perception.messages`, can call it)."""
    return detection.match(ego, map_signs, tolerance, range_tolerance)
