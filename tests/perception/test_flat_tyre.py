"""Flat-tyre detection from the wheel speeds (`perception.flat_tyre`).

Two kinds of input: odometry synthesised from the kinematics of a car rolling without slip
(each wheel's speed from the body's speed, yaw rate and the Ackermann geometry, with the
encoders', gyro's and steering encoder's noise of `world.sensors.odometry`), and the simulated
car in a `World` (a puncture by `EgoBody.puncture`, read by the world's `OdometrySensor`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterator

import numpy as np
import pytest

from perception.flat_tyre import (
    FlatTyreDetector,
    FlatTyreState,
    ackermann_split,
    corrected_speeds,
)
from tests.vehicle import VEHICLE
from world.core.rates import PHYSICS_RATE, TRIGGER_RATE
from world.ego.body import ackermann
from world.frames import Odometry, Wheel
from world.sensors.odometry import GYRO_NOISE, STEERING_NOISE, WHEEL_SPEED_NOISE
from world.spec import (
    EgoSpec,
    EventSpec,
    FlatTire,
    RoadSpec,
    SegmentSpec,
    TimeTrigger,
    WorldSpec,
)
from world.world import World

KPH = 1 / 3.6  # [m/s] per [km/h]
R_WHEEL = 0.33  # [m] the car's rolling radius
R_FLAT = 0.31  # [m] a flat tyre's (the simulated car's)
TRACK, WHEELBASE = 1.40, 2.70  # [m]
DT = 1 / 40  # [s] the runner's odometry rate
ORDER = (Wheel.FRONT_LEFT, Wheel.FRONT_RIGHT, Wheel.REAR_LEFT, Wheel.REAR_RIGHT)


def kinematic_odometry(t: float, speed: float, delta: float, radii: tuple[float, ...],
                       rng: np.random.Generator | None) -> Odometry:
    """A car at forward speed `speed` [m/s] on a bicycle steering angle `delta` [rad],
    rolling without slip: yaw rate v tan(delta) / L; each wheel moves at (v - yaw_rate y,
    yaw_rate x) relative to the rear axle's centre (x = L at the front) and spins at that
    speed over its own rolling radius (`radii`, FL FR RL RR; the odometry reports the
    nominal one)."""
    yaw_rate = speed * math.tan(delta) / WHEELBASE
    spins = []
    for i, radius in enumerate(radii):
        y = TRACK / 2 if i % 2 == 0 else -TRACK / 2
        x = WHEELBASE if i < 2 else 0.0
        spins.append(math.hypot(speed - yaw_rate * y, yaw_rate * x) / radius)
    noise = np.zeros(6) if rng is None else rng.normal(0.0, 1.0, 6)
    measured = [s * (1 + WHEEL_SPEED_NOISE * n) for s, n in zip(spins, noise[:4], strict=True)]
    return Odometry(t=t, wheel_speeds=(measured[0], measured[1], measured[2], measured[3]),
                    wheel_radius=R_WHEEL, yaw_rate=yaw_rate + GYRO_NOISE * float(noise[4]),
                    steering_angle=delta + STEERING_NOISE * float(noise[5]))


def run(samples: Iterator[Odometry], detector: FlatTyreDetector | None = None
        ) -> FlatTyreState | None:
    detector = detector or FlatTyreDetector(VEHICLE)
    found = None
    for odometry in samples:
        found = detector.update(odometry)
    return found


# ---------------------------------------------------------------------------------------
# The turn correction
# ---------------------------------------------------------------------------------------


def test_the_split_is_the_bodys_ackermann() -> None:
    for delta in (-0.5, -0.1, 0.0, 0.02, 0.3):
        assert ackermann_split(delta, WHEELBASE, TRACK) == pytest.approx(
            ackermann(delta, WHEELBASE, TRACK), abs=1e-12)


@pytest.mark.parametrize(("speed", "radius"), [(50 * KPH, 150.0), (50 * KPH, -150.0),
                                               (30 * KPH, 20.0), (15 * KPH, -8.0),
                                               (80 * KPH, 1e9)])
def test_every_wheel_gives_the_same_speed_in_a_turn(speed: float, radius: float) -> None:
    delta = math.atan(WHEELBASE / radius)
    odometry = kinematic_odometry(0.0, speed, delta, (R_WHEEL,) * 4, rng=None)
    raw = [w * R_WHEEL for w in odometry.wheel_speeds]
    corrected = corrected_speeds(odometry, TRACK, WHEELBASE)
    assert corrected == pytest.approx([speed] * 4, rel=1e-9)
    if abs(radius) <= 20.0:  # uncorrected, the outer wheels would look flat
        assert (max(raw) - min(raw)) / speed > 0.03


# ---------------------------------------------------------------------------------------
# Synthetic drives
# ---------------------------------------------------------------------------------------


Profile = Callable[[float], float]
Radii = Callable[[float], tuple[float, ...]]


def drive(seconds: float, speed_at: Profile, delta_at: Profile, radii_at: Radii,
          seed: int) -> Iterator[Odometry]:
    """Odometry at 40 Hz; speed [m/s], steering [rad] and the wheels' radii as functions of
    time."""
    rng = np.random.default_rng(seed)
    for k in range(1, round(seconds / DT) + 1):
        t = k * DT
        yield kinematic_odometry(t, speed_at(t), delta_at(t), radii_at(t), rng)


def const(value: float) -> Profile:
    return lambda t: value


def _flat_at(t0: float, wheel: int, delay: float = 0.25) -> Radii:
    """Radii: all nominal, then `wheel` rolls on the flat radius from t0 + delay (the
    simulated car's rim takes over ~0.25 s after the puncture)."""
    flat = tuple(R_FLAT if i == wheel else R_WHEEL for i in range(4))
    return lambda t: flat if t >= t0 + delay else (R_WHEEL,) * 4


def _normal_driving(t: float) -> tuple[float, float]:
    """60 s at 50 km/h: straight, into a 150 m left curve (steering eased in over 2 s),
    straight, a 150 m right curve, with speed changes of +-1.5 m/s^2 between; then a 20 m
    bend at 30 km/h."""
    curve = math.atan(WHEELBASE / 150.0)
    ease = 2.0  # [s]

    def ramp(t: float, start: float, end: float) -> float:  # 0 -> 1 -> 0
        return min(max((t - start) / ease, 0.0), 1.0, max((end - t) / ease, 0.0))

    delta = curve * (ramp(t, 8.0, 25.0) - ramp(t, 30.0, 45.0))
    speed = 50 * KPH + 1.5 * min(max(t - 25.0, 0.0), 2.0) - 1.5 * min(max(t - 27.0, 0.0), 2.0)
    if t >= 48.0:  # a tight bend, slower
        speed = max(30 * KPH, 50 * KPH - 2.0 * (t - 48.0))
        delta = math.atan(WHEELBASE / 20.0) * ramp(t, 52.0, 60.0)
    return speed, delta


@pytest.mark.parametrize("seed", range(5))
def test_no_flat_in_a_minute_of_normal_driving_with_curves(seed: int) -> None:
    samples = drive(60.0, lambda t: _normal_driving(t)[0], lambda t: _normal_driving(t)[1],
                    lambda t: (R_WHEEL,) * 4, seed)
    detector = FlatTyreDetector(VEHICLE)
    assert run(samples, detector) is None


@pytest.mark.parametrize("kph", [30, 50, 80])
@pytest.mark.parametrize("wheel", range(4))
def test_a_flat_is_found_within_a_second_on_the_straight(kph: int, wheel: int) -> None:
    t0 = 5.0
    found = run(drive(8.0, const(kph * KPH), const(0.0), _flat_at(t0, wheel), seed=kph))
    assert found is not None and found.wheel == ORDER[wheel]
    assert t0 < found.t <= t0 + 1.0
    assert found.excess == pytest.approx(R_WHEEL / R_FLAT - 1, abs=0.02)


@pytest.mark.parametrize("wheel", range(4))
def test_a_flat_is_found_in_a_curve_either_way(wheel: int) -> None:
    for radius in (150.0, -150.0):
        delta = math.atan(WHEELBASE / radius)
        found = run(drive(8.0, const(50 * KPH), const(delta), _flat_at(5.0, wheel),
                          seed=wheel))
        assert found is not None and found.wheel == ORDER[wheel], radius
        assert found.t <= 6.0


def test_too_slow_no_evidence() -> None:
    found = run(drive(8.0, lambda t: 4.0, lambda t: 0.0, _flat_at(1.0, 2), seed=1))
    assert found is None


def test_a_locking_wheel_does_not_make_its_partner_look_flat() -> None:
    """Braking on a slippery patch, the rear left wheel slows 10 % below the ground speed
    for 2 s: its partner is 10 % faster than it, but not faster than the front axle."""
    def radii(t: float) -> tuple[float, ...]:
        return (R_WHEEL, R_WHEEL, R_WHEEL / 0.9 if 2.0 <= t < 4.0 else R_WHEEL, R_WHEEL)

    assert run(drive(6.0, lambda t: 50 * KPH - 2.0 * t, lambda t: 0.0, radii, seed=3)) is None


def test_the_detection_is_latched_and_reset_forgets_it() -> None:
    detector = FlatTyreDetector(VEHICLE)
    found = run(drive(3.0, lambda t: 50 * KPH, lambda t: 0.0, _flat_at(0.5, 1), seed=4),
                detector)
    assert found is not None and found.wheel == Wheel.FRONT_RIGHT
    healed = kinematic_odometry(3.1, 50 * KPH, 0.0, (R_WHEEL,) * 4, rng=None)
    assert detector.update(healed) == found == detector.state
    detector.reset()
    assert detector.state is None and detector.update(healed) is None


def test_a_gap_in_the_samples_restarts_the_timing() -> None:
    """Samples 0.3 s apart (beyond MAX_GAP) give no evidence: 10 of them are not 3 s."""
    detector = FlatTyreDetector(VEHICLE)
    flat = (R_WHEEL, R_WHEEL, R_FLAT, R_WHEEL)
    for k in range(10):
        assert detector.update(kinematic_odometry(0.3 * k, 50 * KPH, 0.0, flat, None)) is None


# ---------------------------------------------------------------------------------------
# The simulated car
# ---------------------------------------------------------------------------------------


def _world(kph: float, events: tuple[EventSpec, ...] = ()) -> World:
    road = RoadSpec(segments=(SegmentSpec(length=3000.0, curvature=0.0, lanes=2,
                                          oncoming_lanes=0, lane_width=3.5, shoulder=2.5),),
                    speed_limit=30.0)
    spec = WorldSpec(road=road, ego=EgoSpec(lane=0, s=20.0, speed=kph * KPH, max_speed=30.0),
                     seed=7, events=events)
    return World(spec)


def _sim(world: World, phases: list[tuple[float, float]], v_set: float
         ) -> tuple[FlatTyreState | None, float]:
    """Drive the world's car through (duration [s], turn radius [m] or inf) phases at 40 Hz
    with fixed steering and a speed-holding torque (test scaffolding, true speed), feeding
    its odometry to a detector. The detection and the largest evidence seen [s]."""
    detector = FlatTyreDetector(VEHICLE)
    found, evidence = None, 0.0
    try:
        for seconds, radius in phases:
            delta = math.atan(WHEELBASE / radius)
            for _ in range(round(seconds * TRIGGER_RATE.hz)):
                truth = world.ego_truth
                world.ego.apply(delta, 90.0 + 1500.0 * 0.33 * 2.0 * (v_set - truth.speed), 0.0)
                odo = world.rig.capture(["odometry"], world.t, truth)[0].frame
                found = found or detector.update(odo)
                evidence = max(evidence, *detector.evidence)
                for _ in range(TRIGGER_RATE.every):
                    world.step()
    finally:
        world.close()
    return found, evidence


@pytest.mark.parametrize(("kph", "wheel"), [(30, Wheel.REAR_LEFT), (50, Wheel.FRONT_RIGHT),
                                            (80, Wheel.REAR_RIGHT), (80, Wheel.FRONT_LEFT)])
def test_a_simulated_flat_is_found_within_a_second(kph: int, wheel: Wheel) -> None:
    world = _world(kph, (EventSpec(TimeTrigger(2.0), FlatTire(wheel)),))
    found, _ = _sim(world, [(4.0, math.inf)], kph * KPH)
    assert found is not None and found.wheel == wheel
    assert 2.0 < found.t <= 3.0


def test_no_flat_in_a_simulated_minute_with_150_m_curves() -> None:
    world = _world(50)
    phases = [(10.0, math.inf), (20.0, 150.0), (5.0, math.inf), (20.0, -150.0),
              (5.0, math.inf)]
    found, evidence = _sim(world, phases, 50 * KPH)
    assert found is None
    assert evidence <= 0.1  # [s] of the 0.5 s


def test_the_world_odometry_is_unchanged_by_a_flat_before_it() -> None:
    """The puncture changes the physics from its check on, never the noise stream."""
    runs = []
    for events in ((), (EventSpec(TimeTrigger(1.0), FlatTire(Wheel.REAR_LEFT)),)):
        world = _world(50, events)
        odometry = []
        try:
            for _ in range(round(2.0 * TRIGGER_RATE.hz)):
                world.ego.apply(0.0, 86.0, 0.0)
                (reading,) = world.rig.capture(["odometry"], world.t, world.ego_truth)
                odometry.append(reading.frame)
                for _ in range(PHYSICS_RATE // TRIGGER_RATE.hz):
                    world.step()
        finally:
            world.close()
        runs.append(odometry)
    before = round(1.0 * TRIGGER_RATE.hz)
    assert runs[0][:before + 1] == runs[1][:before + 1]
    assert dataclasses.replace(runs[0][-1], t=0.0) != dataclasses.replace(runs[1][-1], t=0.0)
