"""GNSS: with odometry (`world.sensors.odometry`), the only pose information the stack gets.

The position of the car centre with white noise (sigma) plus a constant bias, and the
heading with white noise, at the GNSS rate (`world.core.rates.GNSS`), delivered at once.
Noise is drawn from the sensor's own seeded generator, so a run is reproducible.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from world.core.rates import GNSS, Rate
from world.ego.body import EgoTruth
from world.frames import GnssFix, wrap_angle
from world.sensors.sensor import Reading
from world.spec import GnssSpec


@dataclass(frozen=True, slots=True)
class GnssSensor:
    spec: GnssSpec
    rng: np.random.Generator

    @property
    def name(self) -> str:
        return "gnss"

    @property
    def rate(self) -> Rate:
        return GNSS.rate

    @property
    def latency(self) -> float:
        return GNSS.latency

    def capture(self, t: float, ego: EgoTruth) -> Reading:
        return Reading(self.name, self.measure(t, ego))

    def measure(self, t: float, truth: EgoTruth) -> GnssFix:
        noise = self.rng.normal(0.0, 1.0, 3)
        heading = truth.yaw + self.spec.heading_sigma * noise[2]
        return GnssFix(
            t=t,
            x=float(truth.position[0] + self.spec.bias[0] + self.spec.sigma * noise[0]),
            y=float(truth.position[1] + self.spec.bias[1] + self.spec.sigma * noise[1]),
            heading=wrap_angle(heading),
            sigma=self.spec.sigma,
            heading_sigma=self.spec.heading_sigma,
        )
