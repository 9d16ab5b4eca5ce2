"""Tests of the camera traffic-light detector (`perception.lights`): on frames rendered from
the world model (a straight road with traffic light bodies, `tests.perception.light_scene`),
and its pure projection helpers.

The main light stands where the map puts it (`world.map.road.light_head`: 12 m past its
stop line, 1 m right of the paved edge, 3.5 m high, facing the traffic); the ego is posed
on lane 0's centre 10-50 m before it. One world is built for the module and each frame rendered once
(the pose-error cases reuse the frames: the error is in the pose given to the detector).
The renderer is whichever the machine has (EGL or TinyRenderer: both were measured the same).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import replace

import cv2
import numpy as np
import pytest

from perception.lights import (
    HOUSING_DEPTH,
    HOUSING_HEIGHT,
    HOUSING_WIDTH,
    LAMP_DIAMETER,
    LAMP_SPACING,
    SLOT,
    LightParams,
    TrafficLightDetector,
    faces_car,
    head_view,
    housing_corners,
    map_to_vehicle,
    project,
)
from perception.messages import EgoState
from tests.perception.light_scene import LightScene
from tests.perception.render_scene import front_camera
from tests.vehicle import VEHICLE
from world.actors.catalogue import CATALOGUE
from world.frames import CameraFrame
from world.hdmap import LightColour, LightHead
from world.map.road import build_road_map, light_head
from world.scene import traffic_light
from world.spec import ActorSpec, ActorType, RoadSpec, SegmentSpec, TrafficLightSpec

ROAD = RoadSpec(segments=(SegmentSpec(700.0, 0.0, 2, 1, 3.5, 2.5),), speed_limit=50.0 / 3.6)
MAIN_LIGHT = TrafficLightSpec(100.0, 20.0, 3.0, 20.0, 0.0)
MAP = build_road_map(replace(ROAD, features=(MAIN_LIGHT,)))  # MAIN is the map's only light
MAIN = light_head(MAP, MAIN_LIGHT)
FRONT = VEHICLE.front_overhang  # [m] the car's centre to its front bumper
AWAY = replace(MAIN, x=MAIN.x + 150.0, facing=0.0)  # lamps point along the route
LOW = replace(MAIN, x=MAIN.x + 300.0, z=2.8)  # a low post-mounted head, a red van under it
HIDDEN = replace(LOW, x=LOW.x + 200.0)  # the same, the red van in front of it
LEFT = LightHead(MAIN.x + 30.0, 8.0, 3.5, math.pi)  # left of the road, facing the traffic
# a town junction's near corner: the head for the cross street, 10.9 m before MAIN (two
# corners of a one-lane junction apart), lamps facing across the road
SIDE = replace(MAIN, x=MAIN.x - 10.9, facing=0.5 * math.pi)
HEADS = (MAIN, AWAY, LOW, LEFT, SIDE, HIDDEN)
# a red panel van (2.36 m high, painted up to its roof) parked under the low head, its rear
# 0.03 m past the head's post: from the lane it stands right below the housing and fills the
# lower half of the region searched, its paint touching the housing and the green lamp
VAN = ActorSpec("parked", ActorType.CAR, 0, LOW.x + 3.0, LOW.y, 0.0, model=CATALOGUE["van"])
# the same van 3 m before the other low head, between it and the camera: its body hides
# most of the head's green (bottom) lamp (the lamp is not in the pixels)
VAN_IN_FRONT = replace(VAN, id="in front", s=HIDDEN.x - 3.0)
DISTANCES = (10.0, 20.0, 30.0, 40.0, 50.0)  # [m] car centre behind the head
POSE_ERRORS = (  # (forward [m], left [m], heading [deg]) of the estimate's error
    (0.3, 0.0, 1.0), (0.0, 0.3, -1.0), (-0.3, 0.0, -1.0), (0.0, -0.3, 1.0))

Render = Callable[[int, float, LightColour], tuple[CameraFrame, EgoState]]


@pytest.fixture(scope="module")
def scene() -> Iterator[LightScene]:
    built = LightScene(ROAD, HEADS, (VAN, VAN_IN_FRONT))
    yield built
    built.close()


@pytest.fixture(scope="module")
def render(scene: LightScene) -> Render:
    """(head index, distance [m] to it, colour of all lights) -> (frame, true pose), each
    rendered once."""
    cache: dict[tuple[int, float, LightColour], tuple[CameraFrame, EgoState]] = {}

    def frame(head: int, distance: float, colour: LightColour) -> tuple[CameraFrame, EgoState]:
        key = (head, distance, colour)
        if key not in cache:
            cache[key] = scene.render(HEADS[head].x - distance,
                                      dict.fromkeys(range(len(HEADS)), colour))
        return cache[key]

    return frame


@pytest.fixture(scope="module")
def detector() -> TrafficLightDetector:
    return TrafficLightDetector(front_camera(), MAP, VEHICLE)


def lamp_pixel(ego: EgoState, head: LightHead, colour: LightColour) -> tuple[float, float]:
    """[px] where the centre of ``colour``'s lamp of ``head`` images for the pose ``ego``."""
    front = 0.5 * HOUSING_DEPTH
    point = np.array([[head.x + front * math.cos(head.facing),
                       head.y + front * math.sin(head.facing),
                       head.z + (0.5 - SLOT[colour]) * HOUSING_HEIGHT]])
    uv, _ = project(front_camera(), map_to_vehicle(point, ego))
    return float(uv[0, 0]), float(uv[0, 1])


# ---- the world model's light ----------------------------------------------------------------


def test_housing_size_is_the_world_models() -> None:
    assert HOUSING_WIDTH == traffic_light.HOUSING_WIDTH
    assert HOUSING_HEIGHT == traffic_light.HOUSING_HEIGHT
    assert HOUSING_DEPTH == traffic_light.HOUSING_DEPTH
    assert LAMP_DIAMETER == traffic_light.LAMP_DIAMETER
    assert LAMP_SPACING == traffic_light.LAMP_SPACING
    for colour, place in SLOT.items():
        assert place == pytest.approx(0.5 - traffic_light.LAMP_HEIGHT[colour] / HOUSING_HEIGHT)


# ---- which heads: the map's -----------------------------------------------------------------


def _pose_at(x: float) -> EgoState:
    return EgoState(0.0, x, 0.0, 0.0, 10.0, 0.0, 0.0, 0.1)


def test_the_detector_looks_for_the_maps_lights_ahead_of_the_bumper() -> None:
    detector = TrafficLightDetector(front_camera(), MAP, VEHICLE)
    line = MAIN_LIGHT.s
    assert detector.heads_ahead(_pose_at(line - FRONT - 30.0)) == [(0, MAIN)]
    assert detector.heads_ahead(_pose_at(line - FRONT - 59.5)) == [(0, MAIN)]  # 60 m: in
    assert detector.heads_ahead(_pose_at(line - FRONT - 60.5)) == []  # beyond 60 m
    assert detector.heads_ahead(_pose_at(line - FRONT + 0.5)) == [(0, MAIN)]  # just over
    assert detector.heads_ahead(_pose_at(line - FRONT + 2.0)) == []  # over it: not any more
    no_lights = TrafficLightDetector(front_camera(), build_road_map(ROAD), VEHICLE)
    assert no_lights.heads_ahead(_pose_at(50.0)) == []


# ---- rendered frames ------------------------------------------------------------------------


@pytest.mark.parametrize("distance", DISTANCES)
@pytest.mark.parametrize("colour", list(LightColour))
def test_lit_colour_is_found_at_10_to_50_m(
    detector: TrafficLightDetector, render: Render, colour: LightColour, distance: float,
) -> None:
    frame, ego = render(0, distance, colour)
    (found,) = detector.detect_heads(frame, ego, [(7, MAIN)])
    # the map's light 0 is looked for until the bumper is over its stop line (12 m before
    # the head: at 10 m from the head, the car is past it)
    ahead = MAIN_LIGHT.s - (ego.x + FRONT) > -1.0
    assert detector.detect(frame, ego) == ((replace(found, light=0),) if ahead else ())
    assert found.colour is colour
    assert found.light == 7
    assert found.t == frame.t
    assert found.range == pytest.approx(math.hypot(MAIN.x - ego.x, MAIN.y - ego.y))
    assert 0.5 < found.confidence <= 1.0
    u, v = lamp_pixel(ego, MAIN, colour)
    u0, v0, u1, v1 = found.box
    assert u0 - 1 <= u <= u1 + 1
    assert v0 - 1 <= v <= v1 + 1


@pytest.mark.parametrize("error", POSE_ERRORS)
@pytest.mark.parametrize("distance", DISTANCES)
@pytest.mark.parametrize("colour", list(LightColour))
def test_pose_error_of_0_3_m_and_1_deg_is_tolerated(
    detector: TrafficLightDetector, render: Render, colour: LightColour, distance: float,
    error: tuple[float, float, float],
) -> None:
    frame, ego = render(0, distance, colour)
    forward, left, heading = error
    c, s = math.cos(ego.heading), math.sin(ego.heading)
    wrong = replace(ego, x=ego.x + c * forward - s * left, y=ego.y + s * forward + c * left,
                    heading=ego.heading + math.radians(heading))
    (found,) = detector.detect_heads(frame, wrong, [(0, MAIN)])
    assert found.colour is colour


@pytest.mark.parametrize("distance", (20.0, 40.0))
def test_a_light_facing_away_is_not_detected(
    detector: TrafficLightDetector, render: Render, distance: float,
) -> None:
    """Its lamps point along the route: the detector does not look, and there is nothing
    to see (the lamps are culled from behind)."""
    frame, ego = render(1, distance, LightColour.GREEN)
    assert detector.detect_heads(frame, ego, [(1, AWAY)]) == ()
    assert head_view(detector.camera, ego, AWAY, detector.params) is None
    looking = LightParams(max_facing=math.pi)
    view = head_view(detector.camera, ego, AWAY, looking)
    assert view is not None
    looking_detector = TrafficLightDetector(detector.camera, MAP, VEHICLE, looking)
    blobs, hsv = looking_detector.lamp_blobs(frame.rgb, view)
    assert blobs == []
    assert (hsv[..., 2] <= 60).sum() > 10  # the housing's back was in the region


@pytest.mark.parametrize("distance", (5.0, -10.0))
def test_a_light_outside_the_image_is_not_detected(
    detector: TrafficLightDetector, render: Render, distance: float,
) -> None:
    """5 m before the head it is 51 deg right of the axis (the view is +-40 deg); 10 m past
    it, behind the camera."""
    frame, ego = render(0, distance, LightColour.RED)
    assert head_view(detector.camera, ego, MAIN, detector.params) is None
    assert detector.detect_heads(frame, ego, [(0, MAIN)]) == ()


def test_a_light_beyond_max_range_is_not_looked_for(
    detector: TrafficLightDetector, render: Render,
) -> None:
    frame, ego = render(0, 65.0, LightColour.RED)
    assert detector.detect_heads(frame, ego, [(0, MAIN)]) == ()
    near = TrafficLightDetector(detector.camera, MAP, VEHICLE, LightParams(max_range=70.0))
    (found,) = near.detect_heads(frame, ego, [(0, MAIN)])
    assert found.colour is LightColour.RED


@pytest.mark.parametrize("distance", DISTANCES)
def test_a_red_van_under_a_green_light_does_not_turn_it_red(
    detector: TrafficLightDetector, render: Render, distance: float,
) -> None:
    """The van's paint is in the region searched, touching the housing and the green lamp,
    as bright as a lamp (V >= 100) and with a red lamp's hue; it is not saturated enough
    (S ~211 against the lamps' 255). The van stands past the head: in front of it, its body
    would hide the green lamp (`test_a_red_van_hiding_the_green_lamp_is_not_read_as_red`)."""
    frame, ego = render(2, distance, LightColour.GREEN)
    view = head_view(detector.camera, ego, LOW, detector.params)
    assert view is not None
    u0, v0, u1, v1 = view.roi
    hsv = cv2.cvtColor(frame.rgb[v0:v1, u0:u1], cv2.COLOR_RGB2HSV)
    van = (hsv[..., 0] <= 8) & (hsv[..., 1] >= 200) & (hsv[..., 2] >= 100)
    assert van.sum() > 100
    assert hsv[..., 1][van].max() < detector.params.min_saturation
    blobs, _ = detector.lamp_blobs(frame.rgb, view)
    assert {b.colour for b in blobs} == {LightColour.GREEN}
    (found,) = detector.detect_heads(frame, ego, [(2, LOW)])
    assert found.colour is LightColour.GREEN


@pytest.mark.parametrize("distance", DISTANCES)
def test_a_red_van_hiding_the_green_lamp_is_not_read_as_red(
    detector: TrafficLightDetector, render: Render, distance: float,
) -> None:
    """With the van between the camera (1.39 m high) and the head, the line of sight to the
    green lamp (2.5 m high) meets the van's body (2.36 m high, 5.93 m long): at most half of
    the lamp's pixels are left (none at 50 m), the rest of the light's region is red paint
    and sky. The detector reads the green of what is left, or nothing; never the van's red."""
    frame, ego = render(5, distance, LightColour.GREEN)
    clear, clear_ego = render(2, distance, LightColour.GREEN)
    view = head_view(detector.camera, ego, HIDDEN, detector.params)
    clear_view = head_view(detector.camera, clear_ego, LOW, detector.params)
    assert view is not None
    assert clear_view is not None
    blobs, hsv = detector.lamp_blobs(frame.rgb, view)
    clear_blobs, _ = detector.lamp_blobs(clear.rgb, clear_view)
    assert 2 * sum(b.area for b in blobs) <= sum(b.area for b in clear_blobs)
    van = (hsv[..., 0] <= 8) & (hsv[..., 1] >= 200) & (hsv[..., 2] >= 100)
    assert van.sum() > 100
    assert {d.colour for d in detector.detect_heads(frame, ego, [(5, HIDDEN)])} <= {
        LightColour.GREEN}


@pytest.mark.parametrize("distance", (25.0, 35.0, 45.0, 50.0))
def test_a_cross_street_head_seen_side_on_does_not_lend_its_colour(
    detector: TrafficLightDetector, scene: LightScene, distance: float,
) -> None:
    """Beyond ~20 m the side-on head's green lamp falls in the main head's padded region;
    the lamp nearest where the main head's lamps project is the one read."""
    frame, ego = scene.render(MAIN.x - distance, {0: LightColour.RED, 4: LightColour.GREEN})
    view = head_view(detector.camera, ego, MAIN, detector.params)
    assert view is not None
    blobs, _ = detector.lamp_blobs(frame.rgb, view)
    (found,) = detector.detect_heads(frame, ego, [(0, MAIN)])
    assert found.colour is LightColour.RED, [b.colour for b in blobs]


def test_two_lights_come_nearest_first(detector: TrafficLightDetector, render: Render) -> None:
    """From 10 m before the main light, the one left of the road 30 m further on is in view
    too; the one facing away and the one beyond range are not reported."""
    frame, ego = render(0, 10.0, LightColour.YELLOW)
    found = detector.detect_heads(frame, ego, [(3, LEFT), (1, AWAY), (2, LOW), (0, MAIN)])
    assert [d.light for d in found] == [0, 3]
    assert [d.colour for d in found] == [LightColour.YELLOW] * 2
    assert found[0].range < found[1].range


def test_frames_of_another_camera_are_refused(detector: TrafficLightDetector) -> None:
    cam = replace(front_camera(), name="left")
    with pytest.raises(ValueError, match="camera"):
        detector.detect_heads(CameraFrame(0.0, cam, np.zeros((480, 640, 3), np.uint8)),
                              ego_at(MAIN.x - 20.0, 0.0, 0.0), [(0, MAIN)])


def test_black_frame_has_no_light(detector: TrafficLightDetector) -> None:
    frame = CameraFrame(0.0, front_camera(), np.zeros((480, 640, 3), np.uint8))
    assert detector.detect_heads(frame, ego_at(MAIN.x - 20.0, 0.0, 0.0), [(0, MAIN)]) == ()
    assert detector.detect(frame, ego_at(MAIN.x - 20.0, 0.0, 0.0)) == ()


# ---- the pure helpers -----------------------------------------------------------------------


def ego_at(x: float, y: float, heading: float) -> EgoState:
    return EgoState(t=0.0, x=x, y=y, heading=heading, speed=0.0, yaw_rate=0.0,
                    steering_angle=0.0, position_sigma=0.05)


def test_map_to_vehicle_in_a_rotated_pose() -> None:
    """Ego at (10, 20) heading north: a point at (14, 40) is 20 m ahead and 4 m right."""
    out = map_to_vehicle(np.array([[14.0, 40.0, 3.0]]), ego_at(10.0, 20.0, math.pi / 2))
    assert out[0] == pytest.approx([20.0, -4.0, 3.0])


def test_projection_follows_the_pinhole_convention() -> None:
    cam = front_camera()
    m = cam.mount
    points = np.array([[m.x + 10.0, 0.0, m.z], [m.x + 10.0, 1.0, m.z + 2.0],
                       [m.x - 1.0, 0.0, m.z]])
    uv, depth = project(cam, points)
    assert uv[0] == pytest.approx([cam.cx, cam.cy])
    assert uv[1] == pytest.approx([cam.cx - cam.fx * 0.1, cam.cy - cam.fy * 0.2])
    assert depth == pytest.approx([10.0, 10.0, -1.0])


def test_housing_corners_are_the_box_grown() -> None:
    head = LightHead(5.0, 6.0, 3.5, math.pi / 2)  # facing north: depth along y
    corners = housing_corners(head, 0.5)
    assert corners.min(axis=0) == pytest.approx(
        [5.0 - HOUSING_WIDTH / 2 - 0.5, 6.0 - HOUSING_DEPTH / 2 - 0.5, 3.0 - 0.5])
    assert corners.max(axis=0) == pytest.approx(
        [5.0 + HOUSING_WIDTH / 2 + 0.5, 6.0 + HOUSING_DEPTH / 2 + 0.5, 4.0 + 0.5])


@pytest.mark.parametrize(("facing_deg", "faces"), [
    (180.0, True), (122.0, True), (-122.0, True), (118.0, False), (-118.0, False),
    (90.0, False), (0.0, False)])
def test_faces_car_within_60_deg(facing_deg: float, faces: bool) -> None:
    """The car is due west of the head (-x): lamps facing 180 deg look straight at it."""
    head = LightHead(20.0, 0.0, 3.5, math.radians(facing_deg))
    assert faces_car(head, ego_at(0.0, 0.0, 0.0), math.radians(60.0)) is faces


def test_head_view_region_grows_with_the_pads() -> None:
    cam = front_camera()
    ego = ego_at(MAIN.x - 20.0, 0.0, 0.0)
    tight = head_view(cam, ego, MAIN, LightParams(position_pad=0.0, angle_pad=0.0,
                                                  pixel_pad=0))
    loose = head_view(cam, ego, MAIN, LightParams())
    assert tight is not None
    assert loose is not None
    assert tight.housing == loose.housing
    assert tight.housing_px == pytest.approx(cam.fy * HOUSING_HEIGHT / tight.depth, rel=0.05)
    tu0, tv0, tu1, tv1 = tight.roi
    lu0, lv0, lu1, lv1 = loose.roi
    assert lu0 < tu0 and lv0 < tv0 and lu1 > tu1 and lv1 > tv1
    assert tu0 <= tight.housing[0] and tight.housing[2] <= tu1
    pad = cam.fx * math.tan(math.radians(1.5)) + 3  # [px] the angle and pixel pads alone
    assert tu0 - lu0 > pad
