"""Test helper: front-camera frames of a posed ego car on a road with traffic lights.

`LightScene(road, heads, actors)` builds a sensor world of ``road`` with ``actors`` standing
at their initial poses (the world is never stepped) and a traffic light body
(`world.scene.traffic_light`) at each of ``heads``; `render(s, colours)` lights the lamps, poses
the ego on the centre of lane 0 at station ``s`` [m] (as `render_scene.render` does) and
returns the front camera's frame with the ego's true pose as an `EgoState`. Build one scene
per test module (~1.5 s) and `close` it at the end.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

from avsim.scenario.load import load_scenario
from perception.messages import EgoState
from tests.perception.render_scene import BASE_SCENARIO, pose_ego
from world.frames import CameraFrame
from world.hdmap import LightColour, LightHead
from world.scene.traffic_light import TrafficLightBody, add_traffic_light
from world.sensors.setup import Profile, sensor_setup
from world.spec import ActorSpec, RoadSpec
from world.world import World


class LightScene:
    """A sensor world with traffic light bodies, for rendering posed frames."""

    def __init__(self, road: RoadSpec, heads: Sequence[LightHead],
                 actors: tuple[ActorSpec, ...] = (), profile: Profile = Profile.DEFAULT) -> None:
        spec = replace(load_scenario(BASE_SCENARIO).world, road=road, actors=actors, events=())
        self.world = World(spec, sensor_setup(profile))
        self.heads = tuple(heads)
        self.lights: tuple[TrafficLightBody, ...] = tuple(
            add_traffic_light(self.world.client, head) for head in self.heads)

    def render(self, s: float, colours: Mapping[int, LightColour], offset: float = 0.0,
               heading_error: float = 0.0) -> tuple[CameraFrame, EgoState]:
        """The front frame with the ego at station ``s`` of lane 0 (``offset`` [m] left of its
        centre, ``heading_error`` [rad] left of its heading) and light i showing
        ``colours[i]``; and the ego's true pose."""
        for i, colour in colours.items():
            self.lights[i].set_colour(colour)
        world = self.world
        pose_ego(world, 0, s, offset, heading_error)
        truth = world.ego.truth()
        frame = world.rig.capture(["front"], world.t, truth)[0].frame
        assert isinstance(frame, CameraFrame)
        ego = EgoState(t=world.t, x=float(truth.position[0]), y=float(truth.position[1]),
                       heading=float(truth.yaw), speed=0.0, yaw_rate=0.0, steering_angle=0.0,
                       position_sigma=0.05)
        return frame, ego

    def close(self) -> None:
        self.world.close()
