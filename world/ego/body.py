"""The ego car's body in the physics world: joints by name, Ackermann steering, drive, brake.

The car drives through its joints only: the steering hinges get position targets (Ackermann
split of a bicycle angle), the wheel joints get drive torque and a brake. Nothing here sets
the body's pose or velocity after spawn.

Actuator model (per wheel): one joint velocity motor, set when the command changes (at the
control rate) and held by Bullet between commands, so the ego costs no Python per step.
The net torque is ``drive - brake - c m g r - 0.5 rho CdA v^2 r`` (rolling resistance and
drag at the wheel radius r), a quarter per wheel (all-wheel drive, so that `max_accel` stays
well inside the tyres' grip):
- net torque forward: target spin +MAX_WHEEL_SPIN with the net torque as the motor's force
  limit, i.e. a constant forward torque;
- otherwise: target spin 0 with brake + rolling resistance + drag, less any drive torque
  (the net torque's magnitude), as the force limit. A velocity motor with a force limit is
  a Coulomb friction torque: it opposes the wheel's spin up to the limit and holds the car
  at rest. Drag is taken at the speed of the command and acts through the wheels (for a
  rolling car the longitudinal effect is the same as at the body);
- a top-speed governor: no drive torque at or above `EgoParams.max_speed`.
Bullet's default link damping (a force m v (k + k |v|), large at road speeds) is switched
off: drag and rolling resistance are modelled explicitly instead.

Flat tyre (`puncture`, advanced by `update_tyres` at the world's trigger checks). Each wheel
rolls on its tyre's sphere (the rolling radius); inside it, fixed to the wheel, a smaller
sphere of the flat rolling radius (the URDF's `<corner>_rim` link: the rim on the folded
carcass) whose contact is made inert at spawn (`INERT_CONTACT`, no friction) so an intact
car never feels it. A collision shape cannot change at run time, so a puncture moves the
wheel's contact from one sphere to the other, over `EgoParams.deflation_time`:
1. the first `DEFLATE_TYRE_SHARE` of it, the tyre's contact stiffness falls geometrically to
   `TYRE_END_STIFFNESS` of its value: the corner sinks until the rim is just off the road;
2. then the tyre stops colliding and the rim's contact takes the load, its stiffness falling
   geometrically from `RIM_START_STIFFNESS` times the flat tyre's to the flat tyre's (URDF):
   the corner sinks on. From here the wheel rolls on the flat radius: it spins
   `wheel_radius / flat_radius` times faster than the others at the same ground speed.
The flat wheel also gets a rolling-resistance torque `deflated * (c_flat - c) * N * r_flat`
(N its contact's normal force, read when its motor is set): its joint motor's torque is
less that much, so the car needs more drive to hold its speed. That drag is also a yaw
moment toward the flat side, but it does not turn the car: Bullet's tyre contacts take no
slip angle (sideways they hold rigidly up to mu N), so with the steering held straight the
car keeps its heading. A pull would need tyre compliance, which the simulator does not
model for any tyre. The body has no suspension (the tyres' compliance is all of it), so a
corner cannot drop much before the diagonal wheel unloads: the flat corner settles by a
fraction of the tyre's sidewall, not by all of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from vehicle_urdf import URDF_PATH, WHEELS, CarGeometry, read_geometry
from world.core.client import GRAVITY
from world.frames import Indicator, VehicleInfo

AIR_DENSITY = 1.2  # [kg/m^3]
STEER_TORQUE = 4000.0  # [N m] steering hinge servo force limit
STEER_RATE = 1.2  # [rad/s] steering hinge servo speed limit (actuator, not the controller's)
MAX_WHEEL_SPIN = 200.0  # [rad/s] joint velocity cap (Bullet's default would cap the car's
#   speed below the vehicle limits)
INERT_CONTACT = 1e-3  # [N/m], [N s/m] a rim's contact stiffness and damping while its tyre is
#   inflated: it carries next to nothing, and it has no friction
LARGE_THRESHOLD = 1e18  # [m] Bullet's default contact processing threshold (BT_LARGE_FLOAT)
DEFLATE_TYRE_SHARE = 0.25  # [-] share of the deflation time in which the tyre's sphere sinks
TYRE_END_STIFFNESS = 0.35  # [-] the tyre's contact stiffness when the rim takes over, of its
#   own: the corner has sunk until the rim (wheel_radius - flat_radius inside the tyre) is
#   just off the road (the corner lags the falling stiffness; at rest it would sink further)
RIM_START_STIFFNESS = 10.0  # [-] the rim's contact stiffness when it takes over, of the flat
#   tyre's: stiff, so it takes the load without a drop, then softens to the flat tyre's


@dataclass(frozen=True, slots=True)
class EgoParams:
    """The ego car's parameters beyond the URDF's geometry."""

    max_speed: float = 15.0  # [m/s] vehicle limit (the ICCAS car's)
    max_accel: float = 5.0  # [m/s^2] the drive torque is capped to give this on the flat
    rolling_resistance: float = 0.012  # [-] coefficient, F = c m g
    drag_area: float = 0.7  # [m^2] Cd * A
    flat_rolling_resistance: float = 0.15  # [-] coefficient of a flat tyre, F = c N (its load)
    deflation_time: float = 1.0  # [s] a punctured tyre goes flat over this


@dataclass(frozen=True, slots=True, eq=False)
class EgoTruth:
    """Ground truth of the ego body (for sensors, criteria and the recording only)."""

    position: NDArray[np.float64]  # [m] (3,) map frame, the base link origin (car centre)
    quaternion: NDArray[np.float64]  # (4,) x, y, z, w, map frame
    rotation: NDArray[np.float64]  # (3, 3) body -> map frame
    yaw: float  # [rad] map frame, counter-clockwise from +x
    velocity: NDArray[np.float64]  # [m/s] (3,) map frame, at the centre of mass
    speed: float  # [m/s] forward (body x) component of `velocity`
    yaw_rate: float  # [rad/s] about the map's z, counter-clockwise +
    wheel_spin: NDArray[np.float64]  # [rad/s] (4,) FL, FR, RL, RR
    steering_angle: float  # [rad] bicycle-equivalent road-wheel angle from the hinges


def ackermann(delta: float, wheelbase: float, track: float) -> tuple[float, float]:
    """(left, right) hinge angles [rad] for a bicycle road-wheel angle `delta` [rad], left +.

    Both front wheels point at the same turn centre on the rear axle's line:
    tan(delta_side) = L / (R -+ T/2) with R = L / tan(delta).
    """
    if abs(delta) < 1e-9:
        return 0.0, 0.0
    radius = wheelbase / math.tan(delta)  # signed, > 0 turning left
    left = math.atan(wheelbase / (radius - track / 2))
    right = math.atan(wheelbase / (radius + track / 2))
    return left, right


class EgoBody:
    """The URDF car in a world; joints looked up by name, geometry read from the URDF."""

    def __init__(
        self,
        client: BulletClient,
        x: float,
        y: float,
        yaw: float,
        speed: float,
        params: EgoParams,
    ) -> None:
        """Spawn the car at (x, y) [m] in the map frame, heading `yaw` [rad], its base link
        origin at wheel-radius height, rolling forward at `speed` [m/s]."""
        self._c = client
        self.params = params
        self.geometry: CarGeometry = read_geometry(URDF_PATH)
        g = self.geometry
        quat = client.getQuaternionFromEuler([0.0, 0.0, yaw])
        self.body = int(
            client.loadURDF(str(URDF_PATH), [x, y, g.wheel_radius], quat, useFixedBase=False)
        )
        joints = {
            client.getJointInfo(self.body, j)[1].decode(): j
            for j in range(client.getNumJoints(self.body))
        }
        self.joints = joints
        self.wheel_joints = [joints[f"{w}_wheel_joint"] for w in WHEELS]
        self.steer_joints = [joints["front_left_steer_joint"], joints["front_right_steer_joint"]]
        self.links = {client.getJointInfo(self.body, j)[12].decode(): j for j in joints.values()}
        for link in range(-1, client.getNumJoints(self.body)):
            client.changeDynamics(self.body, link, linearDamping=0.0, angularDamping=0.0)
        for j in self.wheel_joints:
            client.changeDynamics(self.body, j, maxJointVelocity=MAX_WHEEL_SPIN)
        self.rim_links = [self.links[f"{w}_rim"] for w in WHEELS]
        self._rim_friction = [float(client.getDynamicsInfo(self.body, rim)[1])
                              for rim in self.rim_links]
        for rim in self.rim_links:  # inert until its tyre goes flat; the contacts Bullet
            # finds before the rim touches are not processed (they would cost every step)
            client.changeDynamics(self.body, rim, contactStiffness=INERT_CONTACT,
                                  contactDamping=INERT_CONTACT, lateralFriction=0.0,
                                  contactProcessingThreshold=0.0)
        self._punctured: dict[int, float] = {}  # wheel index -> [s] sim time of the puncture
        self._on_rim: set[int] = set()  # punctured wheels whose rim carries them
        self._deflated: dict[int, float] = {}  # wheel index -> [-] 0..1, how flat
        self._com_offset = np.array(client.getDynamicsInfo(self.body, -1)[3])
        self._all_joints = list(range(client.getNumJoints(self.body)))
        # bound once: these run at the control rate
        self._base_pose = client.getBasePositionAndOrientation
        self._base_velocity = client.getBaseVelocity
        self._joint_states = client.getJointStates
        self._rotation = client.getMatrixFromQuaternion
        self._motor = client.setJointMotorControl2
        self._motors = client.setJointMotorControlArray
        self.mass = g.mass
        self._roll_torque = params.rolling_resistance * g.mass * GRAVITY * g.wheel_radius
        self._max_drive = g.mass * params.max_accel * g.wheel_radius
        self.drive_torque = 0.0  # [N m] last applied, total
        self.brake_torque = 0.0  # [N m] last applied, total
        self.steer_command = 0.0  # [rad] last commanded bicycle angle
        self.hazard_lights = False  # the hazard lights flash (their switch, as commanded)
        self.indicator = Indicator.OFF  # the turn indicators (their switch, as commanded)
        self._net_torque = 0.0  # [N m] total wheel torque of the last command, + forward
        self._spawn_speed(yaw, speed)
        self.apply(0.0, 0.0, 0.0)

    def _spawn_speed(self, yaw: float, speed: float) -> None:
        """At spawn only: the body and its wheels start rolling at `speed`."""
        if speed == 0.0:
            return
        v = [speed * math.cos(yaw), speed * math.sin(yaw), 0.0]
        self._c.resetBaseVelocity(self.body, v, [0.0, 0.0, 0.0])
        spin = speed / self.geometry.wheel_radius
        for j in self.wheel_joints:
            self._c.resetJointState(self.body, j, 0.0, spin)

    def apply(self, steering_angle: float, drive_torque: float, brake_torque: float) -> None:
        """Command the joints: bicycle steering angle [rad], total drive and brake torque [N m].

        Held by the joint motors until the next call.
        """
        g = self.geometry
        delta = min(max(float(steering_angle), -g.max_steer), g.max_steer)
        left, right = ackermann(delta, g.wheelbase, g.track)
        for joint, target in zip(self.steer_joints, (left, right), strict=True):
            self._motor(
                self.body, joint, pybullet.POSITION_CONTROL, targetPosition=target,
                force=STEER_TORQUE, maxVelocity=STEER_RATE,
            )
        self.steer_command = delta
        self.drive_torque = min(max(float(drive_torque), 0.0), self._max_drive)
        self.brake_torque = max(0.0, float(brake_torque))
        velocity = self._base_velocity(self.body)[0]
        speed = math.hypot(velocity[0], velocity[1])
        if speed >= self.params.max_speed:
            self.drive_torque = 0.0
        drag = 0.5 * AIR_DENSITY * self.params.drag_area * speed**2 * g.wheel_radius
        self._net_torque = self.drive_torque - self.brake_torque - self._roll_torque - drag
        self._set_wheel_motors()

    def _set_wheel_motors(self) -> None:
        """Each wheel's motor: a quarter of the net torque, less a flat tyre's extra rolling
        resistance (`flat_drag`); forward torque spins it up, the rest is a Coulomb torque."""
        quarter = self._net_torque / 4  # [N m]
        torques = [quarter - self.flat_drag(i) if self._punctured else quarter
                   for i in range(4)]
        self._motors(
            self.body, self.wheel_joints, pybullet.VELOCITY_CONTROL,
            targetVelocities=[MAX_WHEEL_SPIN if tq > 0.0 else 0.0 for tq in torques],
            forces=[abs(tq) for tq in torques],
        )

    # -- flat tyres ---------------------------------------------------------------------------

    def set_hazard_lights(self, on: bool) -> None:
        """Switch the hazard lights on or off (held until the next call)."""
        self.hazard_lights = bool(on)

    def set_indicator(self, indicator: Indicator) -> None:
        """Switch the turn indicators (held until the next call)."""
        self.indicator = Indicator(indicator)

    def puncture(self, wheel: str, t: float) -> None:
        """The tyre of `wheel` (a `vehicle_urdf.WHEELS` name) is punctured at sim time `t`
        [s]: it goes flat over `EgoParams.deflation_time` as `update_tyres` is called.
        A tyre already punctured stays as it is."""
        i = WHEELS.index(wheel)
        if i not in self._punctured:
            self._punctured[i] = t
            self.update_tyres(t)

    def update_tyres(self, t: float) -> None:
        """Deflate the punctured tyres to their state at sim time `t` [s] (contact
        stiffness, which sphere rolls) and set the wheel motors again (a flat tyre's drag
        follows its load). Nothing while every tyre holds its air."""
        if not self._punctured:
            return
        for i, t0 in self._punctured.items():
            if self._deflated.get(i) != 1.0:
                self._deflate(i, t - t0)
        self._set_wheel_motors()

    def _deflate(self, i: int, age: float) -> None:
        """Wheel `i`'s tyre `age` [s] after its puncture (the module docstring's steps)."""
        g, c = self.geometry, self._c
        span = self.params.deflation_time
        x = 1.0 if span <= 0.0 else min(max(age / span, 0.0), 1.0)  # [-] how flat
        self._deflated[i] = x
        tyre, rim = self.wheel_joints[i], self.rim_links[i]
        if x < DEFLATE_TYRE_SHARE:
            k = g.tyre_stiffness * TYRE_END_STIFFNESS ** (x / DEFLATE_TYRE_SHARE)
            c.changeDynamics(self.body, tyre, contactStiffness=k, contactDamping=g.tyre_damping)
            return
        if i not in self._on_rim:
            self._on_rim.add(i)
            c.setCollisionFilterGroupMask(self.body, tyre, 0, 0)  # the tyre's sphere: gone
            c.changeDynamics(self.body, rim, lateralFriction=self._rim_friction[i],
                             contactProcessingThreshold=LARGE_THRESHOLD)
        y = (x - DEFLATE_TYRE_SHARE) / (1.0 - DEFLATE_TYRE_SHARE)
        k = g.flat_stiffness * RIM_START_STIFFNESS ** (1.0 - y)
        c.changeDynamics(self.body, rim, contactStiffness=k, contactDamping=g.flat_damping)

    def flat_drag(self, i: int) -> float:
        """[N m] wheel `i`'s extra rolling-resistance torque from its flat tyre (0 while it
        holds air): deflated share * (c_flat - c) * N * r, N [N] its contact's normal force
        after the last step, r the radius it rolls on."""
        x = self._deflated.get(i, 0.0)
        if x == 0.0:
            return 0.0
        on_rim = i in self._on_rim
        link = self.rim_links[i] if on_rim else self.wheel_joints[i]
        load = sum(float(p[9]) for p in self._c.getContactPoints(bodyA=self.body,
                                                                   linkIndexA=link))
        radius = self.geometry.flat_radius if on_rim else self.geometry.wheel_radius
        extra = self.params.flat_rolling_resistance - self.params.rolling_resistance
        return x * extra * load * radius

    @property
    def flat_wheels(self) -> tuple[str, ...]:
        """The wheels (`vehicle_urdf.WHEELS` names) whose tyre is punctured, in wheel order."""
        return tuple(w for i, w in enumerate(WHEELS) if i in self._punctured)

    @property
    def com_offset(self) -> NDArray[np.float64]:
        """[m] (3,) the base's centre of mass in the base link frame (Bullet's base frame
        is there, the link origin is not)."""
        return self._com_offset.copy()

    def base_state(self) -> tuple[tuple[float, ...], tuple[float, ...], list[float]]:
        """Bullet's raw base pose (centre-of-mass frame position, quaternion) and the joint
        positions in joint order: what a mirror of this body needs to look the same."""
        com, quat = self._base_pose(self.body)
        joints = [s[0] for s in self._joint_states(self.body, self._all_joints)]
        return tuple(com), tuple(quat), joints

    def set_base_state(self, com: tuple[float, ...], quat: tuple[float, ...],
                       joints: list[float]) -> None:
        """Pose a MIRROR body (a sensor world's copy, never the simulated ego) as
        `base_state` read it."""
        self._c.resetBasePositionAndOrientation(self.body, com, quat)
        for j, q in zip(self._all_joints, joints, strict=True):
            self._c.resetJointState(self.body, j, q)

    def truth(self) -> EgoTruth:
        """Read the body's true state (link frame origin, not Bullet's centre-of-mass frame)."""
        com, quat = self._base_pose(self.body)
        lin, ang = self._base_velocity(self.body)
        rot = np.array(self._rotation(quat)).reshape(3, 3)
        position = np.asarray(com) - rot @ self._com_offset
        yaw = math.atan2(rot[1, 0], rot[0, 0])
        velocity = np.asarray(lin)
        states = self._joint_states(self.body, self.wheel_joints + self.steer_joints)
        spin = np.array([s[1] for s in states[:4]])
        hinge_l, hinge_r = states[4][0], states[5][0]
        steering = bicycle_angle(hinge_l, hinge_r)
        return EgoTruth(
            position=position,
            quaternion=np.asarray(quat),
            rotation=rot,
            yaw=yaw,
            velocity=velocity,
            speed=float(velocity @ rot[:, 0]),
            yaw_rate=float(ang[2]),
            wheel_spin=spin,
            steering_angle=steering,
        )


def bicycle_angle(left: float, right: float) -> float:
    """The bicycle angle [rad] whose Ackermann split is (left, right): the inverse of
    `ackermann`, from cot(delta) = (cot(left) + cot(right)) / 2."""
    tl, tr = math.tan(left), math.tan(right)
    if tl * tr <= 0.0:  # straight ahead, or hinges passing through zero
        return 0.5 * (left + right)
    return math.atan(2.0 * tl * tr / (tl + tr))


def vehicle_info(geometry: CarGeometry) -> VehicleInfo:
    """The stack's view of the car's dimensions (`world.frames.VehicleInfo`), from the URDF's."""
    return VehicleInfo(length=geometry.body_length, width=geometry.body_width,
                       wheelbase=geometry.wheelbase, track=geometry.track,
                       front_axle=geometry.front_axle, rear_axle=geometry.rear_axle,
                       mass=geometry.mass, wheel_radius=geometry.wheel_radius,
                       max_steer=geometry.max_steer)
