"""Test helper: front-camera frames of a posed ego car, with the lane's ground truth.

`render(road, s, offset, heading_error)` poses the ego car of a (cached) sensor world at
station ``s`` [m] of a lane, ``offset`` [m] left of the lane's centre and ``heading_error``
[rad] left of the lane's heading, renders the front camera and returns the frame with the
true offset, heading error, curvature and width of that lane at the car's actual pose.

The world is never stepped: the ego is placed with `EgoBody.set_base_state` (meant for
mirror worlds that only render), resting on its wheels (base link origin at the car's
`ride_height` above the ground, level). Building a world takes ~1.5 s, so one world is kept
per (road, profile) for the whole test session; NPCs are left out so nothing hides the lines.
"""

from __future__ import annotations

import atexit
import math
from dataclasses import dataclass, replace

import numpy as np

from avsim.scenario.load import load_scenario
from world.frames import CameraFrame, CameraInfo
from world.sensors.setup import Profile, sensor_setup
from world.spec import ActorSpec, RoadSpec
from world.world import World

BASE_SCENARIO = "normal_driving"  # the scenario whose other settings the test worlds use

_WORLDS: dict[tuple[RoadSpec, Profile], World] = {}


@dataclass(frozen=True, slots=True)
class LaneTruth:
    """The ego lane at the car's centre, as `perception.messages.LaneEstimate` has it."""

    s: float  # [m] station of the car's centre
    offset: float  # [m] car centre left of the lane centre
    heading_error: float  # [rad] car heading minus lane heading, left +
    curvature: float  # [1/m] lane centre curvature, left turn +
    width: float  # [m]


@dataclass(frozen=True, slots=True, eq=False)
class Scene:
    frame: CameraFrame
    truth: LaneTruth


def normal_driving_road() -> RoadSpec:
    """The road of `normal_driving`: straight to s 250, R 250 m left to 403, straight, R 50 m
    right from 603 to 672, ..."""
    return load_scenario(BASE_SCENARIO).world.road


def front_camera(profile: Profile = Profile.DEFAULT) -> CameraInfo:
    return sensor_setup(profile).camera("front")


def world_for(road: RoadSpec, profile: Profile = Profile.DEFAULT) -> World:
    """The cached sensor world of ``road`` (built on first use)."""
    key = (road, profile)
    if key not in _WORLDS:
        spec = replace(load_scenario(BASE_SCENARIO).world, road=road, actors=(), events=())
        _WORLDS[key] = World(spec, sensor_setup(profile))
    return _WORLDS[key]


def _wrap(a: float) -> float:
    return math.remainder(a, 2.0 * math.pi)


def pose_ego(world: World, lane: int, s: float, offset: float, heading_error: float) -> None:
    """Place the ego (at rest, level, wheels straight) at the lane pose."""
    ln = world.road.lane(lane)
    xy = ln.position(s, offset)
    yaw = float(ln.heading_at(s)) + heading_error
    rot = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0],
                    [0.0, 0.0, 1.0]])
    origin = np.array([xy[0], xy[1], world.ego.geometry.ride_height])
    com = origin + rot @ world.ego.com_offset
    quat = (0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw))
    joints = [0.0] * len(world.ego.base_state()[2])
    world.ego.set_base_state(tuple(float(c) for c in com), quat, joints)


def lane_truth(world: World, lane: int) -> LaneTruth:
    """The lane's truth at the ego's actual pose (read back from the body)."""
    truth = world.ego.truth()
    ln = world.road.lane(lane)
    s_arr, r_arr = ln.local_coordinates(truth.position[:2])
    s = float(s_arr)
    return LaneTruth(s=s, offset=float(r_arr), heading_error=_wrap(truth.yaw - float(
        ln.heading_at(s))), curvature=float(ln.curvature_at(s)), width=float(ln.width_at(s)))


def render(road: RoadSpec, s: float, offset: float = 0.0, heading_error: float = 0.0,
           lane: int = 0, profile: Profile = Profile.DEFAULT) -> Scene:
    """The front camera's frame with the ego posed on ``road`` (see module doc)."""
    world = world_for(road, profile)
    pose_ego(world, lane, s, offset, heading_error)
    frame = world.rig.capture(["front"], world.t, world.ego.truth())[0].frame
    assert isinstance(frame, CameraFrame)
    return Scene(frame, lane_truth(world, lane))


def close_all() -> None:
    """Disconnect every cached world."""
    while _WORLDS:
        _, world = _WORLDS.popitem()
        world.close()


atexit.register(close_all)


_ACTOR_WORLDS: dict[tuple[RoadSpec, tuple[ActorSpec, ...], Profile], World] = {}


def render_with_actors(road: RoadSpec, actors: tuple[ActorSpec, ...], s: float, lane: int = 0,
                       profile: Profile = Profile.DEFAULT) -> CameraFrame:
    """The front camera's frame with the ego posed at station ``s`` on the centre of ``lane``
    of ``road``, among ``actors`` standing at their initial poses (the world, cached per
    (road, actors, profile) and closed at exit, is never stepped)."""
    key = (road, actors, profile)
    if key not in _ACTOR_WORLDS:
        spec = replace(load_scenario(BASE_SCENARIO).world, road=road, actors=actors, events=())
        _ACTOR_WORLDS[key] = World(spec, sensor_setup(profile))
    world = _ACTOR_WORLDS[key]
    pose_ego(world, lane, s, 0.0, 0.0)
    frame = world.rig.capture(["front"], world.t, world.ego.truth())[0].frame
    assert isinstance(frame, CameraFrame)
    return frame


@atexit.register
def _close_actor_worlds() -> None:
    while _ACTOR_WORLDS:
        _, world = _ACTOR_WORLDS.popitem()
        world.close()
