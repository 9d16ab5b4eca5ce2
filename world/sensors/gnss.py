"""GNSS and odometry: the only pose information the stack gets (issue A).

GNSS: position of the car centre with white noise (sigma) plus a constant bias, heading with
white noise, at 10 Hz. Odometry: wheel spin rates (encoders, 0.5 % scale noise), gyro yaw
rate (0.002 rad/s noise), the steering encoder and the accelerator pedal sensor (exact: a
position the world's ego events hold, `world.ego.events`), at the control rate. Noise is
drawn from the world's seeded generator, so a run is reproducible.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from world.ego.body import EgoTruth
from world.frames import GnssFix, Odometry
from world.spec import GnssSpec

WHEEL_SPEED_NOISE = 0.005  # [-] relative 1-sigma noise of the wheel encoders
GYRO_NOISE = 0.002  # [rad/s] 1-sigma
STEERING_NOISE = 0.001  # [rad] 1-sigma


@dataclass(frozen=True, slots=True)
class GnssSensor:
    spec: GnssSpec
    rng: np.random.Generator

    def measure(self, t: float, truth: EgoTruth) -> GnssFix:
        noise = self.rng.normal(0.0, 1.0, 3)
        heading = truth.yaw + self.spec.heading_sigma * noise[2]
        return GnssFix(
            t=t,
            x=float(truth.position[0] + self.spec.bias[0] + self.spec.sigma * noise[0]),
            y=float(truth.position[1] + self.spec.bias[1] + self.spec.sigma * noise[1]),
            heading=math.atan2(math.sin(heading), math.cos(heading)),
            sigma=self.spec.sigma,
            heading_sigma=self.spec.heading_sigma,
        )


def _released() -> float:
    return 0.0


@dataclass(frozen=True, slots=True)
class OdometrySensor:
    wheel_radius: float  # [m]
    rng: np.random.Generator
    pedal: Callable[[], float] = _released  # [-] 0..1, the accelerator pedal position now

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
        )
