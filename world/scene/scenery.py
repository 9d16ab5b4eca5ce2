"""Roadside scenery as pure layout data: building boxes, speed-limit and stop signs (no PyBullet).

The world builder turns `BuildingBox` into box bodies, `SignPlacement` into a pole with a
round textured plate (`speed_limit_sign_image`) and `StopSignPlacement` into a pole with an
octagonal one (`stop_sign_image`). Signs stand `SIGN_CLEARANCE` beyond the right paved edge
at their station, their plate facing the approaching ego traffic (`roadside_pose`). Every
placement is checked against the HD map, so it holds on arcs and where the cross-section
changes too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from world.frames import to_kph, wrap_angle
from world.hdmap import RoadMap, StopSign
from world.map.rectangles import overlap
from world.spec import BuildingsSpec

FloatArray = NDArray[np.float64]


# -- buildings ----------------------------------------------------------------------------
FRONTAGE_RANGE = (10.0, 30.0)  # [m] along the road
DEPTH_RANGE = (8.0, 20.0)  # [m] away from the road
HEIGHT_RANGE = (6.0, 30.0)  # [m] roof above the ground
MIN_BUILDING_GAP = 1.0  # [m] least gap drawn between neighbours along one side
GAP_JITTER = (0.5, 1.5)  # [-] factor on the mean gap, so the rhythm is not regular
FOOTPRINT_STEP = 0.5  # [m] spacing of the footprint outline samples checked against the road
SHIFT_ITERATIONS = 4  # [-] attempts to move a building out of the setback on an inner curve
SHIFT_MARGIN = 0.01  # [m] extra shift beyond the intrusion found
FACADE_RGB = (
    (0.62, 0.60, 0.56),  # concrete
    (0.72, 0.66, 0.55),  # sandstone
    (0.55, 0.35, 0.28),  # brick
    (0.45, 0.50, 0.56),  # blue-grey glass
    (0.80, 0.78, 0.72),  # plaster
)
FACADE_JITTER = 0.05  # [-] 1-sigma per-channel colour variation

# -- speed-limit signs --------------------------------------------------------------------
SIGN_CLEARANCE = 0.5  # [m] from the right paved edge to the pole
SIGN_PLATE_HEIGHT = 2.0  # [m] plate centre above the ground
SIGN_PLATE_DIAMETER = 0.75  # [m] the round plate's
SIGN_RING_FRACTION = 0.12  # [-] red ring width / plate diameter (Vienna convention ~1/8)
SIGN_TEXT_WIDTH = 0.70  # [-] of the white disc's diameter, for the widest (3-digit) number
SIGN_TEXT_HEIGHT = 0.48  # [-] of the white disc's diameter
SIGN_SUPERSAMPLE = 4  # [-] drawn this much larger, then area-averaged down (anti-aliasing)
# -- stop signs (Vienna convention octagon: red, white border, white STOP) ------------------
STOP_PLATE_WIDTH = 0.75  # [m] across the flats (same size class as the round signs)
STOP_BORDER_FRACTION = 0.04  # [-] white border width / width across the flats
STOP_TEXT_WIDTH = 0.72  # [-] of the red octagon's width across the flats
STOP_TEXT_HEIGHT = 0.30  # [-] of the red octagon's width across the flats
OCTAGON_PHASE = math.pi / 8  # [rad] first corner's angle from the plate's right: flat on top
RED_RGB = (200, 16, 30)  # [0..255]
BLACK_RGB = (10, 10, 10)  # [0..255]
WHITE_RGB = (250, 250, 250)  # [0..255]


@dataclass(frozen=True, slots=True)
class BuildingBox:
    """A box-shaped building standing on the ground."""

    centre: tuple[float, float, float]  # [m] map frame; z = half the height
    half_extents: tuple[float, float, float]  # [m] along the road, across, up (box frame)
    yaw: float  # [rad] of the box's x axis (along the road), ccw from map +x, (-pi, pi]
    rgb: tuple[float, float, float]  # [-] 0..1

    def footprint(self) -> FloatArray:
        """(4, 2) [m] map-frame ground corners, counter-clockwise."""
        hx, hy = self.half_extents[0], self.half_extents[1]
        local: FloatArray = np.array([[hx, hy], [-hx, hy], [-hx, -hy], [hx, -hy]])
        centre: FloatArray = np.array(self.centre[:2])
        return local @ _rotation(self.yaw).T + centre


@dataclass(frozen=True, slots=True)
class SignPlacement:
    """A speed-limit sign on the right of the route, its plate facing ego traffic."""

    s: float  # [m] station of the posting
    kph: int  # the number on the plate [km/h]
    limit: float  # [m/s] the posted limit
    pole_xy: tuple[float, float]  # [m] map frame, foot of the pole
    yaw: float  # [rad] direction the plate's front (its normal) faces: route heading + pi
    plate_height: float = SIGN_PLATE_HEIGHT  # [m] plate centre above the ground
    plate_diameter: float = SIGN_PLATE_DIAMETER  # [m] the round plate's


@dataclass(frozen=True, slots=True)
class StopSignPlacement:
    """A stop sign on the right of the route at a stop line, its plate facing ego traffic."""

    s: float  # [m] station of the stop line
    pole_xy: tuple[float, float]  # [m] map frame, foot of the pole
    yaw: float  # [rad] direction the plate's front (its normal) faces: route heading + pi
    plate_height: float = SIGN_PLATE_HEIGHT  # [m] plate centre above the ground
    plate_width: float = STOP_PLATE_WIDTH  # [m] across the octagon's flats

    @property
    def corner_radius(self) -> float:
        """[m] the octagon's circumradius (centre to a corner)."""
        return 0.5 * self.plate_width / math.cos(math.pi / 8)


def _rotation(yaw: float) -> FloatArray:
    """(2, 2) rotation by `yaw` [rad], counter-clockwise."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s], [s, c]])


# -- buildings ----------------------------------------------------------------------------


def _outline(box: BuildingBox) -> FloatArray:
    """(K, 2) [m] points along the footprint's outline, corners included."""
    corners = box.footprint()
    points = []
    for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / FOOTPRINT_STEP))
        t = np.arange(n)[:, None] / n
        points.append(a + t * (b - a))
    return np.concatenate(points)


def road_intrusion(road_map: RoadMap, points: FloatArray, setback: float, side: int) -> float:
    """[m] how far points (K, 2) reach into the paved area widened by `setback`, measured
    from its edge on `side` (+1 left, -1 right of the route); 0 when all are clear of it.

    A point is clear when its offset from the reference line (at its own station, on the
    piece nearest to it) is right of the right paved edge less the setback or left of the
    left paved edge plus the setback.
    """
    s, d = road_map.local_coordinates(points)
    right, left = road_map.paved_edges(s)
    clear = (d <= right - setback) | (d >= left + setback)
    if bool(np.all(clear)):
        return 0.0
    reach = (left + setback - d) if side > 0 else (d - (right - setback))
    return float(np.max(reach[~clear]))


def _overlaps(box: BuildingBox, others: list[BuildingBox]) -> bool:
    """Whether the box's footprint overlaps any other's (separating-axis test)."""
    a = box.footprint()
    for other in others:
        gap = math.dist(box.centre[:2], other.centre[:2])
        if gap >= math.hypot(*box.half_extents[:2]) + math.hypot(*other.half_extents[:2]):
            continue
        if overlap(a, other.footprint()):
            return True
    return False


def _place(
    road_map: RoadMap,
    side: int,
    s_mid: float,
    size: tuple[float, float, float],
    setback: float,
    rgb: tuple[float, float, float],
) -> BuildingBox | None:
    """A box with its front `setback` beyond the paved edge on `side` (+1 left, -1 right)
    at station s_mid, moved further out while its outline intrudes (inner side of an arc,
    a wider segment next door); None if it cannot be cleared."""
    frontage, depth, height = size
    stations = np.linspace(s_mid - 0.5 * frontage, s_mid + 0.5 * frontage, 9)
    right, left = road_map.paved_edges(stations)
    edge = float(np.max(left)) if side > 0 else float(np.min(right))
    offset = edge + side * (setback + 0.5 * depth)
    heading = float(road_map.heading_at(s_mid))
    for _ in range(SHIFT_ITERATIONS):
        x, y = road_map.position(s_mid, offset)
        box = BuildingBox(
            (float(x), float(y), 0.5 * height),
            (0.5 * frontage, 0.5 * depth, 0.5 * height),
            wrap_angle(heading),
            rgb,
        )
        intrusion = road_intrusion(road_map, _outline(box), setback, side)
        if intrusion == 0.0:
            return box
        offset += side * (intrusion + SHIFT_MARGIN)
    return None


def _facade(rng: np.random.Generator) -> tuple[float, float, float]:
    """[-] 0..1 RGB: one of `FACADE_RGB`, jittered by `FACADE_JITTER` per channel."""
    base = np.asarray(FACADE_RGB[int(rng.integers(len(FACADE_RGB)))])
    r, g, b = np.clip(base + rng.normal(0.0, FACADE_JITTER, 3), 0.0, 1.0)
    return float(r), float(g), float(b)


def layout_buildings(
    road_map: RoadMap, spec: BuildingsSpec, rng: np.random.Generator
) -> list[BuildingBox]:
    """Boxes along both sides of the route (right side first, then left), deterministic
    for the rng's state.

    Walking each side from s = 0 to the route's end: draw a frontage, depth, height and
    facade colour, then a gap so that built frontage / (frontage + gap) averages
    `spec.density`. The box stands `spec.setback` beyond the paved edge (right: the
    shoulder's outer edge; left: the outermost lane's edge), square to the route at its
    middle station. It is moved out if its outline intrudes into the paved area plus
    setback (inner curves), and dropped if it still does or overlaps a placed building.
    """
    if spec.density <= 0.0:
        return []
    gap_factor = (1.0 - min(spec.density, 1.0)) / min(spec.density, 1.0)
    boxes: list[BuildingBox] = []
    for side in (-1, 1):
        s = float(rng.uniform(0.0, FRONTAGE_RANGE[0]))
        while s < road_map.length:
            size = (
                float(rng.uniform(*FRONTAGE_RANGE)),
                float(rng.uniform(*DEPTH_RANGE)),
                float(rng.uniform(*HEIGHT_RANGE)),
            )
            rgb = _facade(rng)
            gap = max(MIN_BUILDING_GAP, size[0] * gap_factor * float(rng.uniform(*GAP_JITTER)))
            s_mid = s + 0.5 * size[0]
            if s_mid <= road_map.length:
                box = _place(road_map, side, s_mid, size, spec.setback, rgb)
                if box is not None and not _overlaps(box, boxes):
                    boxes.append(box)
            s += size[0] + gap
    return boxes


# -- speed-limit signs --------------------------------------------------------------------


def roadside_pose(road_map: RoadMap, s: float) -> tuple[tuple[float, float], float]:
    """([m] pole foot (x, y), [rad] plate yaw) of a sign at station s: the pole
    SIGN_CLEARANCE beyond the right paved edge, the plate's front facing the approaching ego
    traffic (yaw = route heading + pi, wrapped to (-pi, pi])."""
    right, _ = road_map.paved_edges(s)
    x, y = road_map.position(s, float(right) - SIGN_CLEARANCE)
    heading = float(road_map.heading_at(s))
    return (float(x), float(y)), wrap_angle(heading + math.pi)


def layout_speed_limit_signs(road_map: RoadMap) -> list[SignPlacement]:
    """A sign for every speed-limit posting (s = 0 included), in station order, at the
    posting's station (`roadside_pose`)."""
    signs = []
    for posting in road_map.speed_limits:
        pole_xy, yaw = roadside_pose(road_map, posting.s)
        signs.append(
            SignPlacement(
                s=posting.s,
                kph=round(to_kph(posting.limit)),
                limit=posting.limit,
                pole_xy=pole_xy,
                yaw=yaw,
            )
        )
    return signs


def layout_stop_signs(road_map: RoadMap) -> list[StopSignPlacement]:
    """A stop sign for every `StopSign` feature, in station order, at the stop line's
    station (`roadside_pose`)."""
    signs = []
    for feature in road_map.features:
        if isinstance(feature, StopSign):
            pole_xy, yaw = roadside_pose(road_map, feature.s)
            signs.append(StopSignPlacement(s=feature.s, pole_xy=pole_xy, yaw=yaw))
    return signs


def speed_limit_sign_image(kph: int, size: int = 128) -> NDArray[np.uint8]:
    """(size, size, 4) uint8 RGBA picture of a European speed-limit plate: a white disc
    with a red ring and the black number, transparent outside the disc. Drawn with OpenCV
    SIGN_SUPERSAMPLE times larger, then area-averaged down for smooth edges."""
    big = size * SIGN_SUPERSAMPLE
    centre = (big // 2, big // 2)
    radius = big // 2 - SIGN_SUPERSAMPLE  # keep a texel of transparent margin
    inner = round(radius * (1.0 - 2.0 * SIGN_RING_FRACTION))
    rgb = np.full((big, big, 3), WHITE_RGB, dtype=np.uint8)
    alpha = np.zeros((big, big), dtype=np.uint8)
    cv2.circle(alpha, centre, radius, 255, thickness=-1, lineType=cv2.LINE_AA)
    cv2.circle(rgb, centre, radius, RED_RGB, thickness=-1, lineType=cv2.LINE_AA)
    cv2.circle(rgb, centre, inner, WHITE_RGB, thickness=-1, lineType=cv2.LINE_AA)
    _draw_number(rgb, str(kph), centre, 2 * inner)
    rgba = np.dstack([rgb, alpha])
    small = cv2.resize(rgba, (size, size), interpolation=cv2.INTER_AREA)
    return np.asarray(small, dtype=np.uint8)


def _draw_number(rgb: NDArray[np.uint8], text: str, centre: tuple[int, int], disc: int) -> None:
    """Black `text` centred on `centre`, scaled to fit SIGN_TEXT_WIDTH / HEIGHT of a disc
    `disc` pixels across (the width budget is that of three digits)."""
    font = cv2.FONT_HERSHEY_DUPLEX
    (w3, h), _ = cv2.getTextSize("888", font, 1.0, 1)
    scale = min(SIGN_TEXT_WIDTH * disc / w3, SIGN_TEXT_HEIGHT * disc / h)
    thickness = max(1, round(scale * 2.2))
    (w, h), _ = cv2.getTextSize(text, font, scale, thickness)
    origin = (centre[0] - w // 2, centre[1] + h // 2)
    cv2.putText(rgb, text, origin, font, scale, BLACK_RGB, thickness, cv2.LINE_AA)


# -- stop signs ---------------------------------------------------------------------------


def octagon_corners(centre: tuple[float, float], radius: float) -> FloatArray:
    """(8, 2) corners of the stop-sign octagon in image coordinates (x right, y down),
    counter-clockwise on the plate: at angles OCTAGON_PHASE + k pi / 4 from the plate's
    right, `radius` from `centre` (so the top and bottom edges are flat)."""
    angles = OCTAGON_PHASE + np.arange(8) * (math.pi / 4)
    return np.column_stack([centre[0] + radius * np.cos(angles),
                            centre[1] - radius * np.sin(angles)])


def stop_sign_image(size: int = 128) -> NDArray[np.uint8]:
    """(size, size, 4) uint8 RGBA picture of a stop sign: a red octagon with a white border
    and "STOP" in white, transparent outside the octagon (white there in RGB, so a plate's
    edge samples no other colour).

    The octagon's corners are those of `octagon_corners` with the circumradius size / 2:
    the texture coordinates (0.5 + 0.5 cos a, 0.5 - 0.5 sin a) of a plate corner at angle
    a land on the picture's corner. The border is STOP_BORDER_FRACTION of the width across
    the flats; the text fits STOP_TEXT_WIDTH x STOP_TEXT_HEIGHT of the red octagon's width.
    Drawn SIGN_SUPERSAMPLE times larger, then area-averaged down for smooth edges."""
    big = size * SIGN_SUPERSAMPLE
    centre = (0.5 * big, 0.5 * big)
    radius = 0.5 * big
    flats = 2.0 * radius * math.cos(math.pi / 8)
    inner = radius - STOP_BORDER_FRACTION * flats / math.cos(math.pi / 8)
    shift = 4  # fractional bits of the polygon vertices
    outer_pts = np.rint(octagon_corners(centre, radius) * (1 << shift)).astype(np.int32)
    inner_pts = np.rint(octagon_corners(centre, inner) * (1 << shift)).astype(np.int32)
    rgb = np.full((big, big, 3), WHITE_RGB, dtype=np.uint8)
    alpha = np.zeros((big, big), dtype=np.uint8)
    cv2.fillPoly(alpha, [outer_pts], 255, lineType=cv2.LINE_AA, shift=shift)
    cv2.fillPoly(rgb, [inner_pts], RED_RGB, lineType=cv2.LINE_AA, shift=shift)
    red_flats = 2.0 * inner * math.cos(math.pi / 8)
    _draw_fitted(rgb, "STOP", (big // 2, big // 2), STOP_TEXT_WIDTH * red_flats,
                 STOP_TEXT_HEIGHT * red_flats, WHITE_RGB)
    rgba = np.dstack([rgb, alpha])
    small = cv2.resize(rgba, (size, size), interpolation=cv2.INTER_AREA)
    return np.asarray(small, dtype=np.uint8)


def _draw_fitted(rgb: NDArray[np.uint8], text: str, centre: tuple[int, int], width: float,
                 height: float, colour: tuple[int, int, int]) -> None:
    """`text` centred on `centre`, as large as fits `width` x `height` pixels."""
    font = cv2.FONT_HERSHEY_DUPLEX
    (w1, h1), _ = cv2.getTextSize(text, font, 1.0, 1)
    scale = min(width / w1, height / h1)
    thickness = max(1, round(scale * 2.2))
    (w, h), _ = cv2.getTextSize(text, font, scale, thickness)
    origin = (centre[0] - w // 2, centre[1] + h // 2)
    cv2.putText(rgb, text, origin, font, scale, colour, thickness, cv2.LINE_AA)
