"""The physics world of one scenario: road, scenery, the ego car, NPCs and the car's sensors.

`World(spec)` builds everything from a `WorldSpec` into its own `BulletClient`; `step()`
advances physics by one fixed step of `world.core.rates.PHYSICS_RATE` (ego forces, Bullet
step, NPC behaviours, the ego's events). Ground truth for criteria and the recording is in
`world.truth`; the stack only ever sees what the sensor rig (`world.sensors`) measures (the
accelerator pedal an ego event holds is one of the odometry's signals: the world applies no
force for it; a flat tyre an ego event makes is physical, and no signal says it).
The environment (`world.environment`: light, fog, precipitation, the road's friction) is
`CLEAR` until the scenario sets another (`World.set_environment`).
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pybullet
from numpy.typing import NDArray

from world.actors.actor_set import ActorSet
from world.core.client import GROUND_FRICTION, Clock, add_ground, make_client
from world.core.quiet import quiet_c_output
from world.core.rates import ACTOR_RATE, TRIGGER_RATE
from world.core.rendering import attach_renderer
from world.ego.body import EgoBody, EgoParams, EgoTruth
from world.ego.events import EgoEvents
from world.ego.scripted import ScriptedEgo
from world.environment import CLEAR, SceneEnvironment
from world.frames import DriverControls
from world.map.road import build_road_map, light_head
from world.map.signals import light_colour, route_signals
from world.map.town import TownLayout
from world.scene.bump import BumpPlacement, build_speed_bumps, hull_vertices
from world.scene.collision import Box, CollisionShapes, ConvexHull, Cylinder, Part, TriangleMesh
from world.scene.road_marks import build_road_marks
from world.scene.road_mesh import (
    THROUGH_LENGTH,
    TexturedMesh,
    build_road_surface,
    build_through_roads,
)
from world.scene.scenery import (
    OCTAGON_PHASE,
    BuildingBox,
    SignPlacement,
    StopSignPlacement,
    layout_buildings,
    layout_speed_limit_signs,
    layout_stop_signs,
    road_intrusion,
    speed_limit_sign_image,
    stop_sign_image,
)
from world.scene.scenery_objects import object_rgb, object_shape
from world.scene.scenery_roads import build_scenery_roads
from world.scene.texture_rows import aligned_texture
from world.scene.town_scene import Pavement, build_town_scene
from world.scene.traffic_light import TrafficLightBody, add_traffic_light
from world.sensors.camera import Camera, CameraSensor
from world.sensors.gnss import GnssSensor
from world.sensors.lidar import EGO_RAY_GROUP, Lidar, LidarSensor, RayBackend
from world.sensors.odometry import OdometrySensor
from world.sensors.rig import SensorRig
from world.sensors.sensor import Sensor
from world.sensors.setup import LIDAR, SensorSetup
from world.sensors.truth import TruthSensor
from world.spec import (
    SceneryObjectSpec,
    SensorFault,
    TownSpec,
    TrafficLightSpec,
    WorldSpec,
)
from world.truth import RouteTruth, route_truth

SIGN_POLE_RADIUS = 0.04  # [m]
SIGN_SEGMENTS = 24  # triangles in a round sign plate
POLE_RGBA = (0.6, 0.6, 0.62, 1.0)  # [-] galvanised steel


@dataclass(frozen=True, slots=True)
class StaticScene:
    """What was built once: for the recording and the collision criterion."""

    road_meshes: tuple[TexturedMesh, ...]  # the road surfaces, then the painted marks (stop
    #   lines, crosswalks), the scenery roads' surfaces and marks (`scenery<k>_...`) and the
    #   speed bumps' visible surfaces
    buildings: tuple[BuildingBox, ...]
    signs: tuple[SignPlacement, ...]  # speed-limit signs
    ground: int  # body id
    obstacle_bodies: frozenset[int]  # buildings, sign poles and scenery objects: touching
    #   one is a collision
    stop_signs: tuple[StopSignPlacement, ...] = ()
    bumps: tuple[BumpPlacement, ...] = ()
    bump_bodies: frozenset[int] = frozenset()  # speed bumps: driven over, not collisions
    kerb_bodies: frozenset[int] = frozenset()  # a town's kerbed sidewalk slabs (the car
    #   touches one only when it mounts the kerb)
    lights: tuple[TrafficLightSpec, ...] = ()  # every traffic light's plan and head

    @property
    def static_bodies(self) -> frozenset[int]:
        """Every static body with collision but the ground (what the LiDAR can hit)."""
        return self.obstacle_bodies | self.bump_bodies | self.kerb_bodies


@dataclass(frozen=True, slots=True)
class WorldSnapshot:
    """The poses of everything that moves, at one physics step (picklable)."""

    step: int
    ego_com: tuple[float, ...]  # Bullet's base (centre-of-mass) position
    ego_quat: tuple[float, ...]  # x, y, z, w
    ego_joints: list[float]  # joint positions in joint order (wheel spin, steering hinges)
    actors: tuple[tuple[tuple[float, ...], tuple[float, ...]], ...]  # (position, quaternion)
    camera_hidden: tuple[int, ...] = ()  # the actors the cameras do not draw (by index)
    environment: SceneEnvironment = CLEAR  # the environment in effect
    # [rad] each actor's body's joint angles (a walker's legs and arms; () for a rigid one)
    actor_joints: tuple[tuple[float, ...], ...] = ()


class World:
    """One scenario's world in its own physics client."""

    def __init__(self, spec: WorldSpec, sensors: SensorSetup | None = None, *,
                 cameras: bool = True, lidar: bool = True,
                 lidar_backend: RayBackend = RayBackend.EMBREE,
                 privileged: bool = False) -> None:
        """`sensors`: the profile's cameras (the renderer is attached before anything else,
        as EGL requires) and / or LiDAR join the rig's GNSS and odometry in this client;
        `lidar_backend`: what casts the LiDAR's rays (`world.sensors.lidar.RayBackend`);
        `privileged`: the rig also has the `truth` sensor (`world.sensors.truth`)."""
        self.spec = spec
        seeds = np.random.SeedSequence(spec.seed).spawn(4)
        self.client = make_client()
        cameras = cameras and sensors is not None
        self.renderer = attach_renderer(self.client) if cameras else None
        self.clock = Clock()
        self.environment = CLEAR  # the environment in effect (`set_environment`)
        self._step_physics = self.client.stepSimulation  # bound once: called every step
        self.road = build_road_map(spec.road)
        self.signals = route_signals(spec.road, self.road)  # the route's lights (truth)
        self._tmp = tempfile.TemporaryDirectory(prefix="avsim-textures-")
        self._light_bodies: list[TrafficLightBody] = []
        self.shapes = CollisionShapes()  # every body's collision shape, for the LiDAR
        self.scene = self._build_scene(np.random.default_rng(seeds[0]))
        self._light_lamps()
        lane = self.road.lane(spec.ego.lane)
        xy = lane.position(spec.ego.s, spec.ego.offset)
        yaw = float(lane.heading_at(spec.ego.s))
        self.ego = EgoBody(
            self.client, float(xy[0]), float(xy[1]), yaw, spec.ego.speed,
            EgoParams(max_speed=spec.ego.max_speed),
        )
        for link in range(-1, self.client.getNumJoints(self.ego.body)):
            self.client.setCollisionFilterGroupMask(self.ego.body, link, EGO_RAY_GROUP, 0xFFFF)
        self.scripted = ScriptedEgo(self.client, self.ego, self.road, spec.ego.lane,
                                    spec.ego.s, spec.ego.speed,
                                    spec.ego.offset) if spec.ego.scripted else None
        #   the script moves the ego (`world.ego.scripted`), after each physics step
        self.actors = ActorSet(self.client, self.road, spec.actors, self.shapes)
        self._events = EgoEvents(spec.events)
        self.engaged = spec.ego.engaged  # the automated driving function's switch (the
        #   odometry's `engaged`): a storyboard's ActivateControllerAction turns it on
        self.driver = DriverControls()  # the driver's other controls (the odometry's
        #   `driver`): a storyboard's actions on the car under test set them
        self.throttle = 0.0  # [-] 0..1, the accelerator pedal a storyboard's override holds
        self.rig = self._build_rig(sensors, lidar, seeds, lidar_backend)
        if privileged:
            self.rig = SensorRig((*self.rig, TruthSensor(lambda: self.actors.poses,
                                                         lambda: self.unsensed)))
        self.camera_hidden: set[int] = set()  # actors the cameras do not draw (by index)
        self.lidar_hidden: set[int] = set()  # actors the LiDAR's rays pass through
        self._truth: EgoTruth | None = None
        self._route: RouteTruth | None = None
        self._route_station: float | None = spec.ego.s  # [m] the ego's station when last
        #   projected (first: where it starts): the next projection looks near it (a town
        #   route that crosses itself, or runs along its own start street again)
        self.ego_s = self.ego_route.station
        self.started_actions: list[tuple[str, int]] = []  # (actor id, action) at the last check
        self.action_fired_at: dict[tuple[str, int], float] = {}  # [s] (actor id, action) ->
        #   when it fired

    # -- building ----------------------------------------------------------------------------

    def _build_rig(self, setup: SensorSetup | None, lidar: bool,
                   seeds: list[np.random.SeedSequence], backend: RayBackend) -> SensorRig:
        """The car's sensors in this client: the profile's cameras (with a renderer) and
        LiDAR (with `lidar`), GNSS and odometry; each draws its noise from its own child of
        the scenario's seed (LiDAR 3, GNSS 1, odometry 2); a camera's noise (in fog, rain or
        darkness only) from the seed, the stream 4 and the camera's index, and each frame's
        time (`world.sensors.camera_weather`), wherever it renders."""
        ride_height = self.ego.geometry.ride_height
        sensors: list[Sensor] = []
        if setup is not None and self.renderer is not None:
            sensors += [CameraSensor(Camera(self.client, info, self.renderer,
                                            (self.spec.seed % (1 << 64), 4, index)),
                                     setup.timing(info.name), ride_height)
                        for index, info in enumerate(setup.cameras)]
        if setup is not None and lidar:
            caster = Lidar(self.client, setup.lidar, np.random.default_rng(seeds[3]),
                           self.actors.bodies, self.scene.ground,
                           sorted(self.scene.static_bodies), self.shapes, backend)
            sensors.append(LidarSensor(caster, setup.timing(LIDAR), ride_height))
        sensors += [GnssSensor(self.spec.sensors.gnss, np.random.default_rng(seeds[1])),
                    OdometrySensor(self.ego.geometry.wheel_radius,
                                   np.random.default_rng(seeds[2]),
                                   pedal=lambda: self.accelerator_pedal,
                                   engaged=lambda: self.engaged,
                                   driver=lambda: self.driver)]
        return SensorRig(sensors)

    def _build_scene(self, rng: np.random.Generator) -> StaticScene:
        if self.spec.town is not None:
            return self._build_town(self.spec.town, rng)
        ground = add_ground(self.client)
        painted = (*build_road_surface(self.road), *build_through_roads(self.road),
                   *build_road_marks(self.road), *build_scenery_roads(self.spec.scenery_roads))
        for mesh in painted:
            self._add_textured_mesh(mesh.name, mesh.vertices, mesh.indices, mesh.uvs,
                                    mesh.normals, mesh.texture)
        bumps = build_speed_bumps(self.road)
        bump_bodies = frozenset(self._add_bump(bump, mesh) for bump, mesh in bumps)
        meshes = (*painted, *(mesh for _, mesh in bumps))
        buildings: tuple[BuildingBox, ...] = ()
        if self.spec.road.buildings is not None:
            spec = self.spec.road.buildings
            buildings = tuple(b for b in layout_buildings(self.road, spec, rng)
                              if not self._on_through_road(b, spec.setback))
        obstacles = {self._add_building(b) for b in buildings}
        signs = tuple(layout_speed_limit_signs(self.road))
        obstacles |= {self._add_sign(sign) for sign in signs}
        stop_signs = tuple(layout_stop_signs(self.road))
        obstacles |= {self._add_stop_sign(i, sign) for i, sign in enumerate(stop_signs)}
        lights = self.signals
        obstacles |= self._add_lights(lights)
        obstacles |= self._add_scenery_objects(self.spec.scenery_objects)
        return StaticScene(meshes, buildings, signs, ground, frozenset(obstacles),
                           stop_signs, tuple(bump for bump, _ in bumps), bump_bodies,
                           lights=lights)

    def _build_town(self, town: TownSpec, rng: np.random.Generator) -> StaticScene:
        """The town's streets, junctions, stop lines, sidewalks, buildings and stop signs
        (`world.scene.town_scene`) in place of the route's own road: the route (`self.road`) runs
        on the town's streets."""
        ground = add_ground(self.client)
        scene = build_town_scene(TownLayout(town), rng)
        for mesh in scene.surfaces:
            self._add_textured_mesh(mesh.name, mesh.vertices, mesh.indices, mesh.uvs,
                                    mesh.normals, mesh.texture)
        kerbs = frozenset(self._add_pavement(p) for p in scene.pavements)
        obstacles = {self._add_building(b) for b in scene.buildings}
        obstacles |= self._add_alike_stop_signs(scene.stop_signs)
        lights = tuple(a.light for a in TownLayout(town).approaches() if a.light is not None)
        obstacles |= self._add_lights(lights)
        return StaticScene(scene.meshes, scene.buildings, (), ground, frozenset(obstacles),
                           scene.stop_signs, kerb_bodies=kerbs, lights=lights)

    def _add_lights(self, lights: tuple[TrafficLightSpec, ...]) -> set[int]:
        """The traffic lights' bodies (pole and housing: obstacles), lamps lit by
        `_light_lamps`."""
        self._light_bodies = [add_traffic_light(self.client, light_head(self.road, f),
                                                Path(self._tmp.name), self.shapes)
                              for f in lights]
        return {b.body for b in self._light_bodies}

    def _light_lamps(self) -> None:
        """Light each traffic light's lamp for the time now (a change costs a visual
        update, no change nothing)."""
        t = self.clock.t
        for light, body in zip(self.scene.lights, self._light_bodies, strict=True):
            body.set_colour(light_colour(light, t))

    def _add_alike_stop_signs(self, signs: tuple[StopSignPlacement, ...]) -> set[int]:
        """Stop signs of one size (a town's): as `_add_stop_sign` makes them, but every
        pole shares one collision shape and visual, and every plate one textured mesh (in
        the sign's frame: pole foot at the origin, facing +x), each body turned to the sign's
        yaw; the pole bodies are returned. (One plate texture and OBJ file instead of 40 in
        a 3 x 3 town: the world builds in 0.5 s instead of 0.8.)"""
        if not signs:
            return set()
        c = self.client
        first = signs[0]
        if any((s.plate_height, s.plate_width) != (first.plate_height, first.plate_width)
               for s in signs):
            raise ValueError("stop signs of different sizes cannot share one plate")
        top = first.plate_height + first.corner_radius
        shape = self.shapes.create(c, Part(Cylinder(SIGN_POLE_RADIUS, top)))
        pole = c.createVisualShape(pybullet.GEOM_CYLINDER, radius=SIGN_POLE_RADIUS,
                                   length=top, rgbaColor=list(POLE_RGBA))
        vertices, indices, uvs, normals = _plate_mesh(
            (0.0, 0.0), 0.0, first.plate_height, first.corner_radius,
            offset=2 * SIGN_POLE_RADIUS, sides=8, phase=OCTAGON_PHASE)
        rgba = stop_sign_image()
        plate = self._mesh_visual("town_stop_sign", vertices, indices, uvs, normals,
                                  np.ascontiguousarray(rgba[..., :3]))
        poles = set()
        for sign in signs:
            quat = c.getQuaternionFromEuler([0.0, 0.0, sign.yaw])
            poles.add(self.shapes.placed(int(c.createMultiBody(
                0.0, shape, pole, [*sign.pole_xy, top / 2], useMaximalCoordinates=True)), shape))
            c.createMultiBody(0.0, -1, plate, [*sign.pole_xy, 0.0], quat,
                              useMaximalCoordinates=True)
        return poles

    def _add_pavement(self, slab: Pavement) -> int:
        """A kerbed slab's static body at its centre, with the ground's friction: its mesh
        (top and kerb faces) is both the visual and, as a static concave triangle mesh, the
        collision shape (rays cost less against a triangle mesh than against the slab's
        convex hull)."""
        c = self.client
        mesh = slab.mesh
        centre = np.array([*slab.centre, 0.0])
        local = mesh.vertices - centre
        shape = self.shapes.create(c, Part(TriangleMesh(local, mesh.indices.reshape(-1, 3))))
        visual = self._mesh_visual(mesh.name, local, mesh.indices, mesh.uvs, mesh.normals,
                                   mesh.texture)
        body = self.shapes.placed(int(c.createMultiBody(0.0, shape, visual, centre.tolist(),
                                                        useMaximalCoordinates=True)), shape)
        c.changeDynamics(body, -1, lateralFriction=GROUND_FRICTION)
        return body

    def _on_through_road(self, box: BuildingBox, setback: float) -> bool:
        """Whether a building stands on (or within `setback` of) a road left by an exit."""
        points = np.vstack([box.footprint(), box.centre[:2]])
        return any(road_intrusion(self.road.through_road(e, THROUGH_LENGTH), points, setback, 1)
                   > 0.0 for e in self.road.exits)

    def _add_textured_mesh(
        self,
        name: str,
        vertices: NDArray[np.float64],
        indices: NDArray[np.int32],
        uvs: NDArray[np.float64],
        normals: NDArray[np.float64],
        texture: NDArray[np.uint8],
    ) -> int:
        """A visual-only body (no collision: the ground plane carries the car)."""
        visual = self._mesh_visual(name, vertices, indices, uvs, normals, texture)
        return int(self.client.createMultiBody(0.0, -1, visual, useMaximalCoordinates=True))

    def _mesh_visual(
        self,
        name: str,
        vertices: NDArray[np.float64],
        indices: NDArray[np.int32],
        uvs: NDArray[np.float64],
        normals: NDArray[np.float64],
        texture: NDArray[np.uint8],
    ) -> int:
        """A textured mesh visual shape (vertices in the frame of the body it will be on).

        The mesh goes through a Wavefront OBJ file whose material names the texture PNG:
        both renderers load that (the EGL plugin drops meshes given as vertex arrays, and
        ignores textures attached afterwards with `changeVisualShape`). Its rows are made
        whole multiples of 4 bytes first (`world.scene.texture_rows`)."""
        texture, uvs = aligned_texture(texture, uvs)
        folder = Path(self._tmp.name)
        cv2.imwrite(str(folder / f"{name}.png"), cv2.cvtColor(texture, cv2.COLOR_RGB2BGR))
        _write_obj(folder / f"{name}.obj", vertices, indices, uvs, normals, f"{name}.png")
        return int(self.client.createVisualShape(pybullet.GEOM_MESH,
                                                 fileName=str(folder / f"{name}.obj")))

    def _add_building(self, b: BuildingBox) -> int:
        c = self.client
        shape = self.shapes.create(c, Part(Box(b.half_extents)))
        visual = c.createVisualShape(
            pybullet.GEOM_BOX, halfExtents=list(b.half_extents), rgbaColor=[*b.rgb, 1.0]
        )
        quat = c.getQuaternionFromEuler([0.0, 0.0, b.yaw])
        return self.shapes.placed(int(c.createMultiBody(0.0, shape, visual, list(b.centre),
                                                        quat, useMaximalCoordinates=True)), shape)

    def _add_scenery_objects(self, objects: tuple[SceneryObjectSpec, ...]) -> set[int]:
        """A static body with collision for each scenery object; alike objects (same shape
        and colour) share one collision shape and one visual. A prism's visual is its
        bounding box (a visual mesh would go through a file: `_mesh_visual`)."""
        c = self.client
        shapes: dict[tuple[object, ...], tuple[int, int]] = {}
        bodies: set[int] = set()
        for obj in objects:
            key = (obj.round, obj.half_extents, obj.hull, obj.type)
            if key not in shapes:
                rgba = [*object_rgb(obj), 1.0]
                shape = self.shapes.create(c, Part(object_shape(obj)))
                if obj.round:
                    visual = c.createVisualShape(pybullet.GEOM_CYLINDER,
                                                 radius=obj.half_extents[0],
                                                 length=2.0 * obj.half_extents[2],
                                                 rgbaColor=rgba)
                else:
                    visual = c.createVisualShape(pybullet.GEOM_BOX,
                                                 halfExtents=list(obj.half_extents),
                                                 rgbaColor=rgba)
                shapes[key] = (shape, int(visual))
            shape, visual = shapes[key]
            quat = c.getQuaternionFromEuler([0.0, 0.0, obj.yaw])
            bodies.add(self.shapes.placed(int(c.createMultiBody(
                0.0, shape, visual, list(obj.centre), quat, useMaximalCoordinates=True)),
                shape))
        return bodies

    def _add_pole(self, xy: tuple[float, float], top: float) -> int:
        """A sign pole standing on the ground up to `top` [m], with collision."""
        c = self.client
        shape = self.shapes.create(c, Part(Cylinder(SIGN_POLE_RADIUS, top)))
        visual = c.createVisualShape(pybullet.GEOM_CYLINDER, radius=SIGN_POLE_RADIUS,
                                     length=top, rgbaColor=list(POLE_RGBA))
        return self.shapes.placed(int(c.createMultiBody(0.0, shape, visual, [*xy, top / 2],
                                                        useMaximalCoordinates=True)), shape)

    def _add_sign(self, sign: SignPlacement) -> int:
        """A pole (with collision) and a round textured plate facing the traffic."""
        pole = self._add_pole(sign.pole_xy, sign.plate_height + sign.plate_diameter / 2)
        vertices, indices, uvs, normals = _plate_mesh(
            sign.pole_xy, sign.yaw, sign.plate_height, sign.plate_diameter / 2,
            offset=2 * SIGN_POLE_RADIUS, sides=SIGN_SEGMENTS)
        rgba = speed_limit_sign_image(sign.kph)
        self._add_textured_mesh(f"sign_{sign.kph}_{sign.s:.0f}", vertices, indices, uvs,
                                normals, np.ascontiguousarray(rgba[..., :3]))
        return pole

    def _add_stop_sign(self, index: int, sign: StopSignPlacement) -> int:
        """A pole (with collision) and an octagonal stop plate facing the traffic."""
        pole = self._add_pole(sign.pole_xy, sign.plate_height + sign.corner_radius)
        vertices, indices, uvs, normals = _plate_mesh(
            sign.pole_xy, sign.yaw, sign.plate_height, sign.corner_radius,
            offset=2 * SIGN_POLE_RADIUS, sides=8, phase=OCTAGON_PHASE)
        rgba = stop_sign_image()
        self._add_textured_mesh(f"stop_sign_{index}", vertices, indices, uvs, normals,
                                np.ascontiguousarray(rgba[..., :3]))
        return pole

    def _add_bump(self, bump: BumpPlacement, mesh: TexturedMesh) -> int:
        """A speed bump's static body, placed at its centre with the ground's friction: the
        convex hull of its prism for collision (`createCollisionShape` with vertices and no
        indices makes a convex hull) and its surface `mesh` (map frame) as the visual, in
        the body's frame (a body without a visual shape makes the EGL plugin try to draw
        the collision mesh from a file, and warn)."""
        c = self.client
        shape = self.shapes.create(c, Part(ConvexHull(hull_vertices(bump))))
        cos, sin = math.cos(bump.yaw), math.sin(bump.yaw)
        rotation = np.array([[cos, -sin, 0.0], [sin, cos, 0.0], [0.0, 0.0, 1.0]])
        local = (mesh.vertices - np.array([*bump.centre, 0.0])) @ rotation
        visual = self._mesh_visual(mesh.name, local, mesh.indices, mesh.uvs,
                                   mesh.normals @ rotation, mesh.texture)
        quat = c.getQuaternionFromEuler([0.0, 0.0, bump.yaw])
        body = self.shapes.placed(int(c.createMultiBody(
            0.0, shape, visual, [*bump.centre, 0.0], quat, useMaximalCoordinates=True)), shape)
        c.changeDynamics(body, -1, lateralFriction=GROUND_FRICTION)
        return body

    # -- stepping ----------------------------------------------------------------------------

    @property
    def t(self) -> float:
        """[s] simulated time."""
        return self.clock.t

    @property
    def ego_truth(self) -> EgoTruth:
        """The ego's true state after the last step (read once per step, when asked)."""
        if self._truth is None:
            self._truth = self.ego.truth()
        return self._truth

    @property
    def ego_route(self) -> RouteTruth:
        """The ego's true centre, front axle and tyres on the route after the last step (one
        projection per step, shared by the NPC triggers, the criteria and the log)."""
        if self._route is None:
            self._route = route_truth(self.ego_truth, self.ego.geometry, self.road.line,
                                      self._route_station)
            self._route_station = self._route.station
        return self._route

    @property
    def accelerator_pedal(self) -> float:
        """[-] 0..1, the accelerator pedal position an ego event or a storyboard's override
        (`throttle`) holds now, the further pressed (0: released), as of the last trigger
        check; what `odometry` measures. No force comes with it."""
        return max(self._events.pedal, self.throttle)

    @property
    def event_fired_at(self) -> tuple[float | None, ...]:
        """[s] per ego event (`spec.events` order): when it fired, None if not yet."""
        return self._events.fired_at

    @property
    def event_ended_at(self) -> tuple[float | None, ...]:
        """[s] per ego event: when it ended (an override: the pedal released; a sensor
        fault: its duration over), None while not."""
        return self._events.ended_at

    @property
    def sensor_faults(self) -> tuple[SensorFault, ...]:
        """The sensor faults running now (as of the last trigger check), in the order they
        fired: what the sensing pipeline does to the data (`world.sensors.faults`)."""
        return self._events.faults

    @property
    def started_events(self) -> tuple[int, ...]:
        """Indices of the ego events that fired at the last trigger check."""
        return self._events.started

    def step(self) -> None:
        """One physics step (the ego's joint motors hold the last command), then the NPCs and
        the ego's events.

        Triggers (NPC actions and ego events) are checked at `TRIGGER_RATE` against the
        ego's true station; NPC motion is integrated and the bodies are moved at `ACTOR_RATE`
        (kinematic bodies: the contact query between moves sees the last placed pose, 1/120 s
        old at most). Ego events set the pedal the odometry reads, and puncture tyres: the
        ego body deflates those, advanced at each check (`EgoBody.update_tyres`).
        """
        self._step_physics()
        if self.scripted is not None:
            self.scripted.step(self.clock.t, self.clock.dt)
        self.clock.advance()
        self._truth = None
        self._route = None
        if self.clock.step % TRIGGER_RATE.every == 0:
            self.ego_s = self.ego_route.station
            self.started_actions = self.actors.fire_triggers(
                self.clock.t, self.ego_s, self.ego.geometry.body_length
            )
            for started in self.started_actions:
                self.action_fired_at.setdefault(started, self.clock.t)
            self._events.update(self.clock.t, self.ego_s)
            for wheel in self._events.started_flats:
                self.ego.puncture(wheel.value, self.clock.t)
            self.ego.update_tyres(self.clock.t)
            self._light_lamps()
        if self.clock.step % ACTOR_RATE.every == 0:
            ego = None
            if self.actors.town_drivers:  # they keep their distance to the ego too
                x, y, _ = self.client.getBasePositionAndOrientation(self.ego.body)[0]
                ego = (x, y, 0.5 * self.ego.geometry.body_length)
            self.actors.step(self.clock.t, ACTOR_RATE.every * self.clock.dt, ego, self.ego_s)

    def snapshot(self) -> WorldSnapshot:
        """The moving bodies' poses now (for a mirror world that only renders).

        The ego events' state (the accelerator pedal) is left out: it changes nothing that
        is drawn or ray-cast, and a mirror world is never stepped, so it never needs it."""
        com, quat, joints = self.ego.base_state()
        actors = tuple(self.client.getBasePositionAndOrientation(b) for b in self.actors.bodies)
        return WorldSnapshot(self.clock.step, com, quat, joints, actors,
                             tuple(sorted(self.camera_hidden)), self.environment,
                             self.actors.joints())

    def set_environment(self, env: SceneEnvironment) -> None:
        """The environment in effect from now on: the cameras and the LiDAR see through it,
        and the road's surfaces (the ground, speed bumps, kerbed slabs) take its friction,
        `GROUND_FRICTION` x `friction_scale` (Bullet multiplies it with the tyre's)."""
        if env.friction_scale != self.environment.friction_scale:
            friction = GROUND_FRICTION * env.friction_scale
            for body in (self.scene.ground, *sorted(self.scene.bump_bodies),
                         *sorted(self.scene.kerb_bodies)):
                self.client.changeDynamics(body, -1, lateralFriction=friction)
        self.environment = env
        for sensor in self.rig:
            if isinstance(sensor, CameraSensor):
                sensor.camera.environment = env
            elif isinstance(sensor, LidarSensor):
                sensor.lidar.extinction = env.extinction

    @property
    def unsensed(self) -> set[int]:
        """The indices of the actors no sensor can see now: hidden from the sensors (a
        VisibilityAction) or out of the world (deleted, or a town driver that arrived)."""
        return self.lidar_hidden | set(np.flatnonzero(self.actors.gone).tolist())

    def set_actor_visibility(self, i: int, cameras: bool, lidar: bool) -> None:
        """Whether the cameras draw actor `i` and the LiDAR's rays meet it. Its body stays
        in the physics (contacts) and in the truth either way."""
        for hidden, seen in ((self.camera_hidden, cameras), (self.lidar_hidden, lidar)):
            if seen:
                hidden.discard(i)
            else:
                hidden.add(i)
        self._hide_from_sensors()

    def _hide_from_sensors(self) -> None:
        bodies = self.actors.bodies
        for sensor in self.rig:
            if isinstance(sensor, CameraSensor):
                sensor.camera.hidden = frozenset(bodies[i] for i in self.camera_hidden)
            elif isinstance(sensor, LidarSensor):
                sensor.lidar.hide(frozenset(bodies[i] for i in self.lidar_hidden))

    def apply_snapshot(self, snap: WorldSnapshot) -> None:
        """Pose this world as `snap` says: for a MIRROR world, never one being simulated."""
        self.clock.step = snap.step
        self.ego.set_base_state(snap.ego_com, snap.ego_quat, snap.ego_joints)
        for body, (position, quat) in zip(self.actors.bodies, snap.actors, strict=True):
            self.client.resetBasePositionAndOrientation(body, position, quat)
        if snap.actor_joints:
            self.actors.set_joints(snap.actor_joints)
        if set(snap.camera_hidden) != self.camera_hidden:
            self.camera_hidden = set(snap.camera_hidden)
            self._hide_from_sensors()
        if snap.environment != self.environment:
            self.set_environment(snap.environment)
        self.client.performCollisionDetection()  # bring the ray-test broadphase up to date
        self._light_lamps()
        self._truth = None
        self._route = None

    def close(self) -> None:
        if self.client is not None:
            with quiet_c_output():  # the EGL plugin says goodbye on the C stdout
                self.client.disconnect()
        self._tmp.cleanup()


def _write_obj(path: Path, vertices: NDArray[np.float64], indices: NDArray[np.int32],
               uvs: NDArray[np.float64], normals: NDArray[np.float64], texture: str) -> None:
    """A triangle mesh as a Wavefront OBJ (one index per vertex for position, texture
    coordinate and normal) with a material file that maps `texture` (a file name beside it)."""
    material = path.with_suffix(".mtl")
    material.write_text(f"newmtl painted\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nmap_Kd {texture}\n")
    faces = indices.reshape(-1, 3) + 1
    with path.open("w") as f:
        f.write(f"mtllib {material.name}\nusemtl painted\n")
        np.savetxt(f, vertices, fmt="v %.6f %.6f %.6f")
        # our uvs put (0, 0) at the texture's first row (the top of the PNG); an OBJ's v runs
        # up from the bottom row
        np.savetxt(f, np.column_stack([uvs[:, 0], 1.0 - uvs[:, 1]]), fmt="vt %.6f %.6f")
        np.savetxt(f, normals, fmt="vn %.6f %.6f %.6f")
        np.savetxt(f, np.repeat(faces, 3, axis=1), fmt="f %d/%d/%d %d/%d/%d %d/%d/%d")


def _plate_mesh(
    pole_xy: tuple[float, float], yaw: float, height: float, radius: float, offset: float,
    sides: int, phase: float = 0.0,
) -> tuple[NDArray[np.float64], NDArray[np.int32], NDArray[np.float64], NDArray[np.float64]]:
    """A two-sided triangle fan for a sign plate, `offset` [m] in front of the pole, its
    centre `height` [m] above the ground, facing `yaw`: a regular polygon of `sides` corners
    `radius` [m] from the centre, the first at `phase` [rad] counter-clockwise from the
    viewer's right (many sides: a round plate). A corner at angle a has the texture
    coordinates (0.5 + 0.5 cos a, 0.5 - 0.5 sin a)."""
    n = sides
    normal = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    across = np.array([-math.sin(yaw), math.cos(yaw), 0.0])  # a viewer's right
    centre = np.array([*pole_xy, height]) + offset * normal
    angles = phase + np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    ring = centre + radius * (  # u runs to the viewer's right (`across`), v down
        np.cos(angles)[:, None] * across + np.sin(angles)[:, None] * np.array([0, 0, 1.0])
    )
    vertices = np.vstack([centre, ring])
    uvs = np.vstack([[0.5, 0.5], np.column_stack([0.5 + 0.5 * np.cos(angles),
                                                   0.5 - 0.5 * np.sin(angles)])])
    front = [(0, 1 + i, 1 + (i + 1) % n) for i in range(n)]
    back = [(0, 1 + (i + 1) % n, 1 + i) for i in range(n)]
    indices = np.array(front + back, dtype=np.int32)
    normals = np.tile(normal, (n + 1, 1))
    return vertices, indices, uvs, normals
