"""Traffic lights in a camera frame: the lit lamp's colour, looked for where the map says the
light is.

`TrafficLightDetector.detect(frame, ego)` takes one `CameraFrame`, (H, W, 3) RGB, and the
stack's pose estimate at its time, picks the map's light heads ahead (`world.hdmap.LightHead`)
and returns a `LightDetection` (the lit colour) for each head it sees, nearest first.
Classical and stateless, one frame at a time: colour blobs in the light's expected image
region. OpenCV and numpy only; the housing's size is the standard one, not read from the
world model.

The light: a dark housing `HOUSING_WIDTH` wide, `HOUSING_HEIGHT` tall and `HOUSING_DEPTH`
deep, centred on the head's point (the yellow lamp's centre), with three round lamps
`LAMP_DIAMETER` across, `LAMP_SPACING` apart: red on top, yellow, green at the bottom. The
head's ``facing`` [rad] is the map-frame yaw of the lamps' outward normal.

1. **Which heads** (`heads_ahead`, `head_view`): the map's lights (`RoadMap.traffic_lights`)
   whose stop line is at most ``stop_line_ahead`` ahead of the front bumper along the road
   (or less than ``stop_line_behind`` behind it), and whose head is within ``max_range`` of
   the car's centre, faces the car (the lamps' normal within ``max_facing`` of the direction
   from the head to the car: from behind or side-on the lamps cannot be seen), lies beyond
   the camera's near plane and has its centre project inside the image.

2. **Where** (`head_view`): the housing's eight corners go from the map frame to the vehicle
   frame by the pose estimate (x, y, heading; the ground at z = 0, the body's pitch and roll
   unknown), to the camera frame by the mount, and to pixels (u = cx - fx Y / X, v = cy - fy
   Z / X): their bounding box is the expected housing. The region searched (ROI) is the
   housing grown by ``position_pad`` on every side before projecting (the position error),
   then by fx tan(``angle_pad``) (the heading error and the body's pitch) and ``pixel_pad``
   in the image.

3. **Lamp blobs** (`lamp_blobs`): in the ROI, in OpenCV's 8-bit HSV (hue 0..179 in 2 deg
   units, S and V 0..255), the pixels with V >= ``min_value``, S >= ``min_saturation`` and a
   hue in ``red_hue``, ``yellow_hue`` or ``green_hue``; each colour's 8-connected components,
   up to ``max_blob_factor`` times the lamp's expected area (+ 4 px), are the candidates.
   Saturation is what sets a lit lamp apart: lamps render fully saturated, while painted
   surfaces (a red car as bright as a lamp, a truck, a pedestrian, a stop sign, grass,
   facades) stay below ``min_saturation``; unlit lamps and the housing are dark. The hue
   bands also leave out the stop sign's red and the orange of obstacle blocks.

4. **The lit lamp**: the candidates are tried nearest first to where their colour's lamp
   projects (a lamp of another head seen side-on through the padded ROI lies off it), then
   largest first. When the housing is at least ``slot_min_px`` tall, a blob's place down it
   must match its colour's (`SLOT`: red in the top third, yellow in the middle, green at the
   bottom) within ``slot_tolerance`` of its height, else the next blob is tried. The housing
   for that is its dark silhouette (V <= ``dark_max_value``, with the lamps) around the blob
   when that is about the housing's projected height (``silhouette_ratio``), else the
   projection: the body's pitch, which the pose lacks, shifts the projection by fx tan(pitch)
   pixels while a lamp spacing shrinks as fx `LAMP_SPACING` / X.

5. **Confidence** in [0, 1]: the product of a size factor (0.5 + 0.5 x the blob's area over
   the lamp's expected area, at most 1), a uniqueness factor (the blob's share of all the
   candidates' pixels in the ROI) and a position factor (1 when the place was checked, 0.8
   when the housing was too small to tell).

``range`` is the horizontal distance from the car's centre to the head by the map and the
pose estimate (a lamp of a few pixels is too small to range by).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from perception.messages import EgoState, LightDetection
from world.frames import CameraFrame, CameraInfo, VehicleInfo
from world.hdmap import LightColour, LightHead, RoadMap

HOUSING_WIDTH = 0.35  # [m] (standard size)
HOUSING_HEIGHT = 1.0  # [m]
HOUSING_DEPTH = 0.25  # [m]
LAMP_DIAMETER = 0.22  # [m]
LAMP_SPACING = 0.30  # [m] centre to centre, red on top, yellow at the head's centre
SLOT = {  # [-] a lamp centre's place down the housing: 0 at its top, 1 at its bottom
    LightColour.RED: 0.5 - LAMP_SPACING / HOUSING_HEIGHT,
    LightColour.YELLOW: 0.5,
    LightColour.GREEN: 0.5 + LAMP_SPACING / HOUSING_HEIGHT,
}

FloatArray = NDArray[np.float64]
UInt8Array = NDArray[np.uint8]
Box = tuple[int, int, int, int]  # [px] u0, v0, u1, v1 (exclusive)


@dataclass(frozen=True, slots=True)
class LightParams:
    """Thresholds of `TrafficLightDetector`, by step of the module docstring."""

    # -- which heads
    stop_line_ahead: float = 60.0  # [m] a light is looked for while its stop line is at
    #   most this far ahead of the front bumper ...
    stop_line_behind: float = 1.0  # [m] ... and less than this behind it
    max_range: float = 60.0  # [m] car centre to head, horizontal
    max_facing: float = math.radians(60.0)  # [rad] lamps' normal vs the direction to the car
    # -- where: the ROI
    position_pad: float = 0.5  # [m] pose position error allowed for
    angle_pad: float = math.radians(1.5)  # [rad] heading (and body pitch) error allowed for
    pixel_pad: int = 3  # [px] added in the image, after the two pads above
    # -- lamp colour, OpenCV 8-bit HSV: hue [2 deg units] 0..179, saturation and value 0..255
    min_saturation: int = 240  # [0..255] lit lamps render fully saturated, paint stays below
    min_value: int = 100  # [0..255] unlit lamps and the housing are darker
    red_hue: tuple[int, int] = (0, 8)  # [2 deg] inclusive band
    yellow_hue: tuple[int, int] = (15, 30)  # [2 deg]
    green_hue: tuple[int, int] = (55, 95)  # [2 deg]
    max_blob_factor: float = 4.0  # [-] blob area / the lamp's expected area (+ 4 px) at most
    # -- position check
    slot_min_px: float = 12.0  # [px] housing height from which the lamp's place is checked
    slot_tolerance: float = 0.15  # [-] of the housing's height
    dark_max_value: int = 60  # [0..255] housing silhouette: V at most this
    silhouette_ratio: tuple[float, float] = (0.7, 1.4)  # [-] its height / the projected one

    def hues(self) -> dict[LightColour, tuple[int, int]]:
        return {LightColour.RED: self.red_hue, LightColour.YELLOW: self.yellow_hue,
                LightColour.GREEN: self.green_hue}


@dataclass(frozen=True, slots=True)
class HeadView:
    """Where one map head should appear in the image (`head_view`)."""

    range: float  # [m] car centre to the head, horizontal
    depth: float  # [m] the head's centre along the optical axis
    centre: tuple[float, float]  # [px] (u, v) of the head's centre
    housing: tuple[float, float, float, float]  # [px] u0, v0, u1, v1 of the projected housing
    roi: Box  # [px] the region searched, clipped to the image (may be empty)

    @property
    def housing_px(self) -> float:
        """[px] the projected housing's height."""
        return self.housing[3] - self.housing[1]


@dataclass(frozen=True, slots=True)
class LampBlob:
    """One lit-lamp candidate in a ROI (image pixels)."""

    colour: LightColour  # the hue band it fell in
    area: int  # [px]
    box: Box  # [px] in the image
    centroid: tuple[float, float]  # [px] (u, v), pixel centres at i + 0.5


# ---- geometry (pure) ------------------------------------------------------------------------


def map_to_vehicle(points: FloatArray, ego: EgoState) -> FloatArray:
    """(N, 3) map-frame points [m] -> the vehicle frame of the pose ``ego`` (x forward from
    the car's centre, y left, z up from the ground, taken level)."""
    c, s = math.cos(ego.heading), math.sin(ego.heading)
    dx, dy = points[:, 0] - ego.x, points[:, 1] - ego.y
    return np.column_stack([c * dx + s * dy, -s * dx + c * dy, points[:, 2]])


def project(camera: CameraInfo, points: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(N, 3) vehicle-frame points [m] -> pixels (N, 2) (u, v) and their depth (N,) [m] along
    the optical axis (a point behind the camera has depth <= 0 and a meaningless pixel)."""
    m = camera.mount
    sensor = (points - np.array([m.x, m.y, m.z])) @ m.rotation()
    depth = sensor[:, 0]
    safe = np.where(np.abs(depth) > 1e-9, depth, 1e-9)
    uv = np.column_stack([camera.cx - camera.fx * sensor[:, 1] / safe,
                          camera.cy - camera.fy * sensor[:, 2] / safe])
    return uv, depth


def housing_corners(head: LightHead, grow: float = 0.0) -> FloatArray:
    """(8, 3) [m] map frame: the corners of the head's housing box, grown by ``grow`` on
    every side."""
    half = np.array([HOUSING_DEPTH, HOUSING_WIDTH, HOUSING_HEIGHT]) / 2.0 + grow
    signs = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], float)
    local = signs * half
    c, s = math.cos(head.facing), math.sin(head.facing)
    return np.column_stack([head.x + c * local[:, 0] - s * local[:, 1],
                            head.y + s * local[:, 0] + c * local[:, 1], head.z + local[:, 2]])


def faces_car(head: LightHead, ego: EgoState, max_angle: float) -> bool:
    """Whether the head's lamps face the car: their normal within ``max_angle`` [rad] of the
    direction from the head to the car's centre."""
    dx, dy = ego.x - head.x, ego.y - head.y
    distance = math.hypot(dx, dy)
    if distance < 1e-9:
        return False
    cos = (dx * math.cos(head.facing) + dy * math.sin(head.facing)) / distance
    return cos >= math.cos(max_angle)


def head_view(camera: CameraInfo, ego: EgoState, head: LightHead,
              params: LightParams) -> HeadView | None:
    """Where ``head`` should appear, or None when it is not looked for (too far, not facing
    the car, behind the camera, its centre outside the image)."""
    centre_v = map_to_vehicle(np.array([[head.x, head.y, head.z]]), ego)[0]
    distance = math.hypot(centre_v[0], centre_v[1])
    if distance > params.max_range or not faces_car(head, ego, params.max_facing):
        return None
    grown = map_to_vehicle(housing_corners(head, params.position_pad), ego)
    (centre_uv,), (depth,) = project(camera, centre_v[None, :])
    uv, depths = project(camera, np.vstack([map_to_vehicle(housing_corners(head), ego), grown]))
    if depths.min() <= camera.near:
        return None
    u, v = centre_uv
    if not (0.0 <= u < camera.width and 0.0 <= v < camera.height):
        return None
    housing = uv[:8]
    pad = camera.fx * math.tan(params.angle_pad) + params.pixel_pad
    lo, hi = uv[8:].min(axis=0) - pad, uv[8:].max(axis=0) + pad
    roi = (max(0, math.floor(lo[0])), max(0, math.floor(lo[1])),
           min(camera.width, math.ceil(hi[0])), min(camera.height, math.ceil(hi[1])))
    return HeadView(range=distance, depth=float(depth), centre=(float(u), float(v)),
                    housing=(float(housing[:, 0].min()), float(housing[:, 1].min()),
                             float(housing[:, 0].max()), float(housing[:, 1].max())), roi=roi)


# ---- the detector -----------------------------------------------------------------------------


class TrafficLightDetector:
    """Finds the lit lamp of the map's traffic lights in the frames of one camera (see the
    module docstring)."""

    def __init__(self, camera: CameraInfo, road: RoadMap, vehicle: VehicleInfo,
                 params: LightParams | None = None) -> None:
        """`road`: the HD map whose lights are looked for; `vehicle`: the car's size (the
        stop lines are measured from its front bumper)."""
        self.camera = camera
        self.road = road
        self.vehicle = vehicle
        self.params = params or LightParams()
        self._station: float | None = 0.0  # [m] the car's station at the last look (first:
        #   the route's start; a town route crossing itself passes a point twice:
        #   `ReferenceLine.project`)

    def heads_ahead(self, ego: EgoState) -> list[tuple[int, LightHead]]:
        """(id, head) of the map's lights whose stop line is at most ``stop_line_ahead``
        ahead of the front bumper, or less than ``stop_line_behind`` behind it, by station
        along the road (an id indexes `RoadMap.traffic_lights`)."""
        p = self.params
        station = float(self.road.local_coordinates(np.array([ego.x, ego.y]),
                                                     self._station)[0])
        self._station = station
        front = station + self.vehicle.front_overhang
        return [(i, light.head) for i, light in enumerate(self.road.traffic_lights)
                if -p.stop_line_behind < light.s - front <= p.stop_line_ahead]

    def detect(self, frame: CameraFrame, ego: EgoState) -> tuple[LightDetection, ...]:
        """The lit colour of each light of the map ahead (`heads_ahead`) seen in
        ``frame``, nearest first. ``ego`` is the pose estimate at the frame's time."""
        return self.detect_heads(frame, ego, self.heads_ahead(ego))

    def detect_heads(self, frame: CameraFrame, ego: EgoState,
                     heads: Sequence[tuple[int, LightHead]]) -> tuple[LightDetection, ...]:
        """The lit colour of each of ``heads`` ((id, head) pairs, map frame) seen in
        ``frame``, nearest first. ``ego`` is the pose estimate at the frame's time."""
        if frame.info != self.camera:
            raise ValueError(f"frame of camera {frame.info.name!r}, detector of "
                             f"{self.camera.name!r} (or different calibration)")
        found = []
        for light, head in heads:
            view = head_view(self.camera, ego, head, self.params)
            if view is None:
                continue
            detection = self._detect_in(frame, light, view)
            if detection is not None:
                found.append(detection)
        return tuple(sorted(found, key=lambda d: d.range))

    def lamp_blobs(self, rgb: UInt8Array, view: HeadView) -> tuple[list[LampBlob], UInt8Array]:
        """The lit-lamp candidates in ``view``'s ROI of an (H, W, 3) RGB image, largest
        first, and the ROI's HSV."""
        p = self.params
        u0, v0, u1, v1 = view.roi
        hsv = np.asarray(cv2.cvtColor(np.ascontiguousarray(rgb[v0:v1, u0:u1]),
                                      cv2.COLOR_RGB2HSV), dtype=np.uint8)
        lamp_px = self.camera.fx * LAMP_DIAMETER / max(view.depth, 1e-9)  # [px] diameter
        max_area = p.max_blob_factor * math.pi / 4.0 * lamp_px**2 + 4.0
        blobs = []
        for colour, (h0, h1) in p.hues().items():
            mask = cv2.inRange(hsv, (h0, p.min_saturation, p.min_value), (h1, 255, 255))
            n, _, stats, centroids = cv2.connectedComponentsWithStats(mask, connectivity=8)
            for i in range(1, n):
                x, y, w, h, area = (int(a) for a in stats[i])
                if area > max_area:
                    continue
                cu, cv = centroids[i]
                blobs.append(LampBlob(colour, area, (u0 + x, v0 + y, u0 + x + w, v0 + y + h),
                                      (u0 + float(cu) + 0.5, v0 + float(cv) + 0.5)))
        blobs.sort(key=lambda b: -b.area)
        return blobs, hsv

    def slot(self, blob: LampBlob, hsv: UInt8Array, view: HeadView) -> float | None:
        """[-] the blob's place down the housing (0 top, 1 bottom), or None when the housing
        is too small in the image to tell."""
        if view.housing_px < self.params.slot_min_px:
            return None
        top, bottom = self._silhouette(blob, hsv, view) or (
            view.centre[1] - 0.5 * view.housing_px, view.centre[1] + 0.5 * view.housing_px)
        return (blob.centroid[1] - top) / (bottom - top)

    def _silhouette(self, blob: LampBlob, hsv: UInt8Array,
                    view: HeadView) -> tuple[float, float] | None:
        """[px] top and bottom of the dark housing around ``blob``, or None when the dark
        region there is not about the housing's projected height."""
        p = self.params
        u0, v0 = view.roi[0], view.roi[1]
        dark = (hsv[..., 2] <= p.dark_max_value) | (
            (hsv[..., 1] >= p.min_saturation) & (hsv[..., 2] >= p.min_value))
        _, labels = cv2.connectedComponents(dark.astype(np.uint8), connectivity=8)
        bu0, bv0, bu1, bv1 = blob.box
        inside = labels[bv0 - v0:bv1 - v0, bu0 - u0:bu1 - u0].ravel()
        label = int(np.bincount(inside[inside > 0]).argmax())  # the blob's own component
        rows = np.nonzero((labels == label).any(axis=1))[0]
        top, bottom = v0 + float(rows[0]), v0 + float(rows[-1]) + 1.0
        ratio = (bottom - top) / view.housing_px
        lo, hi = p.silhouette_ratio
        return (top, bottom) if lo <= ratio <= hi else None

    def _detect_in(self, frame: CameraFrame, light: int,
                   view: HeadView) -> LightDetection | None:
        u0, v0, u1, v1 = view.roi
        if u1 <= u0 or v1 <= v0:
            return None
        blobs, hsv = self.lamp_blobs(frame.rgb, view)
        total = sum(b.area for b in blobs)
        # the blob nearest where its colour's lamp projects comes first: a lamp of another
        # head seen side-on through the ROI lies off it (the ROI is padded for pose error)
        blobs.sort(key=lambda b: (_off_lamp(b, view), -b.area))
        for blob in blobs:
            place = self.slot(blob, hsv, view)
            if place is not None and abs(place - SLOT[blob.colour]) > self.params.slot_tolerance:
                continue
            lamp_px = self.camera.fx * LAMP_DIAMETER / view.depth
            size = min(1.0, 0.5 + 0.5 * blob.area / (math.pi / 4.0 * lamp_px**2))
            position = 1.0 if place is not None else 0.8
            confidence = size * position * blob.area / total
            return LightDetection(t=frame.t, light=light, colour=blob.colour,
                                  range=view.range, confidence=confidence, box=blob.box)
        return None


def _off_lamp(blob: LampBlob, view: HeadView) -> float:
    """[px] from the blob's centroid to where its colour's lamp projects in ``view``."""
    top, bottom = view.housing[1], view.housing[3]
    v = top + SLOT[blob.colour] * (bottom - top)
    return math.hypot(blob.centroid[0] - view.centre[0], blob.centroid[1] - v)
