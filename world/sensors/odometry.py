"""Odometry: with GNSS (`world.sensors.gnss`), the only pose information the stack gets.

Wheel spin rates (encoders, with a relative scale noise), gyro yaw rate, the steering
encoder (each with white noise: `WHEEL_SPEED_NOISE`, `GYRO_NOISE`, `STEERING_NOISE`) and the
accelerator pedal sensor (exact: a position the world's ego events
hold, `world.ego.events`, or a storyboard's override) and the driver's other controls
(`world.frames.DriverControls`, exact), sampled together at the odometry rate
(`world.core.rates.ODOMETRY`), delivered at once. Noise is drawn from the sensor's own seeded
generator, so a run is reproducible.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from world.core.rates import ODOMETRY, Rate
from world.ego.body import EgoTruth
from world.frames import DriverControls, Odometry
from world.sensors.sensor import Reading

WHEEL_SPEED_NOISE = 0.005  # [-] relative 1-sigma noise of the wheel encoders
GYRO_NOISE = 0.002  # [rad/s] 1-sigma
STEERING_NOISE = 0.001  # [rad] 1-sigma


def _released() -> float:
    return 0.0


def _on() -> bool:
    return True


def _at_rest() -> DriverControls:
    return DriverControls()


@dataclass(frozen=True, slots=True)
class OdometrySensor:
    wheel_radius: float  # [m]
    rng: np.random.Generator
    pedal: Callable[[], float] = _released  # [-] 0..1, the accelerator pedal position now
    engaged: Callable[[], bool] = _on  # the automated driving function's switch now
    driver: Callable[[], DriverControls] = _at_rest  # the driver's other controls now

    @property
    def name(self) -> str:
        return "odometry"

    @property
    def rate(self) -> Rate:
        return ODOMETRY.rate

    @property
    def latency(self) -> float:
        return ODOMETRY.latency

    def capture(self, t: float, ego: EgoTruth) -> Reading:
        return Reading(self.name, self.measure(t, ego))

    def measure(self, t: float, truth: EgoTruth) -> Odometry:
        noise = self.rng.normal(0.0, 1.0, 6)
        spins = truth.wheel_spin * (1.0 + WHEEL_SPEED_NOISE * noise[:4])
        return Odometry(
            t=t,
            wheel_speeds=(float(spins[0]), float(spins[1]), float(spins[2]), float(spins[3])),
            wheel_radius=self.wheel_radius,
            yaw_rate=truth.yaw_rate + GYRO_NOISE * float(noise[4]),
            steering_angle=truth.steering_angle + STEERING_NOISE * float(noise[5]),
            accelerator_pedal=self.pedal(),
            engaged=self.engaged(),
            driver=self.driver(),
        )
