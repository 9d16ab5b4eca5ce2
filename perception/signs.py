"""Stop signs in a camera frame, by colour and shape, and their match with the map's signs.

`StopSignDetector.detect(frame)` takes one `world.frames.CameraFrame` and returns the stop
signs it sees as `perception.messages.SignDetection` (vehicle frame, nearest first). It is
classical and stateless, one frame at a time; `match_sign` pairs a detection with a sign of
the HD map. Only OpenCV and numpy: nothing here knows the simulator (the plate's size is
the standard one, `STOP_PLATE_DIAMETER`, not read from the world model).

The sign: a regular octagon, flat on top, `STOP_PLATE_DIAMETER` (0.75 m) across the flats,
red with a white border (`STOP_BORDER_FRACTION` of the width, 4 %) and the white word STOP,
its centre ~2 m above the ground. The red field, the part the colour test finds, is
``STOP_FIELD_WIDTH = 0.69 m`` across.

1. **Red mask** in OpenCV's 8-bit HSV (hue 0..179 in units of 2 deg): hue <= ``hue_low_max``
   (6, i.e. 12 deg) or >= ``hue_high_min`` (170), saturation >= ``min_saturation`` (100) and
   value >= ``min_value`` (60). Measured in rendered frames (EGL and TinyRenderer alike):
   the plate's red is H 177-178, S ~235, V ~150; an anti-aliased edge pixel half on the sky
   has S ~110, so the floor of 100 cuts the plate close to its true outline (the range
   estimate relies on that). Brick facades render at H 8-14, S 120-175 (the narrow low hue
   band leaves them out); NPC cars at H ~2, S ~211 (they pass the colour test and fail the
   shape tests). A **morphological close** (3 x 3) mends the one-pixel gaps that the STOP
   letters or a pole drawn through a distant plate leave. Then the **external contours** of
   the closed mask.

2. **Per blob** (a contour and its filled inside, the "plate"):

   - size: the plate's bounding box at least ``min_size_px`` on its smaller side and at
     most ``max_size_px`` on its larger, both computed from the intrinsics: the red field
     at ``max_range`` (50 m) and at ``min_range`` (3 m) (a 640 x 480, 80 deg camera has
     fx = 381 px: 5.3 px at 50 m, 7 px at 40 m, 13 px at 20 m, 88 px at 3 m);
   - colour: a saturated core (some pixel with S >= ``core_saturation``, 190: the plate's
     red keeps S >= 200 out to 45 m, a lit brick wall reaches ~175) and red over at least
     ``min_red_fill`` (0.6) of the plate: the STOP letters are a small part of the field
     (red fill 0.8-0.95), whereas a speed-limit sign's red ring encloses a white disc (red
     fill ~0.4);
   - shape: bounding-box aspect (width / height) within ``aspect`` (0.75..1.33); solidity
     (contour area / convex hull area) >= ``min_solidity`` (0.85); extent (plate pixels /
     bounding-box pixels) within ``extent`` (0.70..0.92): an octagon fills 0.83 of its
     box, a rectangle (the back of a red car, a facade) ~1; and, when the blob is at least
     ``polygon_min_px`` (20 px) across so that corners are resolvable, the convex hull's
     ``approxPolyDP`` (epsilon ``polygon_epsilon``, 2.5 % of its perimeter) has 7..9
     vertices. Below that the circularity of the hull (4 pi A / P^2, an octagon 0.95, a
     square 0.79) must reach ``min_circularity`` (0.80);
   - white inside: when the blob is at least ``white_min_px`` (14 px) across, where the
     letters are resolved, low-saturation bright pixels (S <= ``white_max_saturation``, V >=
     ``min_value``) make at least ``min_white_fill`` (2 %) of the plate (the STOP letters);
     at a distance they blur into pink and the cue is not asked for.

3. **Position**. The plate faces the traffic, so it stands about parallel to the image
   plane of a forward camera and its apparent size gives the depth. The red field's
   width in pixels comes from the plate's pixel count N (a count of pixel centres inside
   the outline is an unbiased area, unlike the extremes of the contour, which lose a pixel
   per side, and it averages over the whole outline, which matters at 7 px): the
   octagon's area is ``OCTAGON_AREA_FACTOR`` (2 (sqrt 2 - 1) = 0.828) times its width
   squared, so ``width_px = sqrt(N / 0.828)``. (A plate seen at an angle a is foreshortened
   by cos a across, so its range comes out 1 / sqrt(cos a) too long: +2 % at 20 deg.) The
   depth along the optical axis is ``X = fy STOP_FIELD_WIDTH / width_px``; the plate's
   centroid (u, v) gives ``Y = -(u - cx) X / fx`` and ``Z = -(v - cy) X / fy`` in the
   camera's frame, and the mount (position and yaw / pitch / roll) takes that to the
   vehicle frame of the car's centre. ``range`` is the horizontal distance from the car's
   centre. A plate whose centre then lies outside ``plate_height`` (1.0..4.0 m above the
   ground) is not a sign: a red patch of a sign's apparent size but another true size sits
   at the wrong depth, which puts it underground or in the air.

4. **Confidence** in [0, 1]: the mean of a colour score (red fill), a shape score (extent
   and solidity near the octagon's, the polygon's vertex count or the circularity) and the
   white cue's (1 when the letters are seen, 0.5 when too small to tell), times a size
   factor rising from 0.6 at ``min_size_px`` to 1 at ``polygon_min_px``.

Measured (the default profile's 640 x 480 front camera, a straight road, the plate 4.75 m
right of the car's centre, EGL and TinyRenderer): found from 8 m (nearer, it leaves the
80 deg view) to 45 m (at 50 m it is 5 px across); range error within -3 .. +3 %, lateral
within 0.2 m, height within 0.1 m; nothing found on a speed-limit sign, red NPC cars or a
built-up roadside; ~0.8 ms per frame (0.7 ms without a sign), the HSV conversion most of it.

`match_sign` (the same as `SignDetection.match`, which the planner can reach) moves a
detection into the map frame with the ego's pose and takes the nearest map sign whose
offset from it lies within ``tolerance`` (5 m) across the line of sight and within
``tolerance + range_tolerance * range`` (15 % of the range more) along it: the apparent size
gives the range to a few percent (a pixel of a 7 px plate is 14 %), the bearing much better.
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
    """Thresholds of `StopSignDetector` (see the module docstring for each)."""

    # -- red mask, OpenCV 8-bit HSV: hue [2 deg units] 0..179, saturation and value 0..255
    hue_low_max: int = 6
    hue_high_min: int = 170
    min_saturation: int = 100
    min_value: int = 60
    close_kernel: int = 3  # [px] square structuring element of the morphological close
    # -- size, from the intrinsics
    min_range: float = 3.0  # [m] nearest plate looked for (sets the largest blob)
    max_range: float = 50.0  # [m] farthest plate looked for (sets the smallest blob)
    # -- colour
    core_saturation: int = 190
    min_red_fill: float = 0.6  # [-] red pixels / plate pixels
    white_max_saturation: int = 80
    white_min_px: float = 14.0  # [px] blob size from which the letters are asked for
    min_white_fill: float = 0.02  # [-] white pixels / plate pixels
    # -- shape
    aspect: tuple[float, float] = (0.75, 1.33)  # [-] box width / height
    min_solidity: float = 0.85
    extent: tuple[float, float] = (0.70, 0.92)  # [-] plate pixels / box pixels
    polygon_min_px: float = 20.0  # [px] blob size from which the octagon's corners are sought
    polygon_epsilon: float = 0.025  # [-] approxPolyDP tolerance / hull perimeter
    polygon_vertices: tuple[int, int] = (7, 9)
    min_circularity: float = 0.80
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
        """Every red blob of a plausible size in an (H, W, 3) RGB image, measured."""
        hsv = np.asarray(cv2.cvtColor(rgb, cv2.COLOR_RGB2HSV), dtype=np.uint8)
        mask = self.red_mask(hsv)
        closed = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, self._kernel)
        contours, _ = cv2.findContours(closed, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
        blobs = []
        for contour in contours:
            u0, v0, w, h = cv2.boundingRect(contour)
            if min(w, h) < self.min_size_px or max(w, h) > self.max_size_px:
                continue
            blobs.append(self._measure_blob(contour, hsv, mask, (u0, v0, w, h)))
        return blobs

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
