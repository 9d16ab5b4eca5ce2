"""GNSS: with odometry (`world.sensors.odometry`), the only pose information the stack gets.

A receiver's fix of the car centre's position and heading at the GNSS rate
(`world.core.rates.GNSS`), delivered at once. Its errors (`world.spec.GnssSpec`, with the
named presets `world.spec.GNSS_PRESETS`):

- position, per map axis: the constant ``bias``, plus a wandering bias, a first-order
  Gauss-Markov process (Brown & Hwang, *Introduction to Random Signals and Applied Kalman
  Filtering*, the usual model of the slowly varying GNSS error: atmosphere, orbits,
  multipath): ``b_k+1 = a b_k + sqrt(1 - a^2) bias_sigma w_k`` with ``a = exp(-dt /
  bias_tau)``, started from its stationary distribution ``N(0, bias_sigma^2)``; plus white
  noise ``sigma``;
- heading: white noise ``heading_sigma``; with ``velocity_sigma`` > 0 the heading is the
  course over ground (a single antenna), whose noise grows as ``atan(velocity_sigma /
  speed)`` at low speed (pi / 2 at a standstill: no heading);
- outages: each starts with probability ``1 - exp(-dropout_rate dt)`` between fixes and ends
  with ``1 - exp(-dt / dropout_duration)``; a fix in an outage is flagged invalid.

The fix states the receiver's own accuracy estimate (`GnssSpec.stated_sigma`, the heading's
1-sigma), not the error it actually has. Every random number comes from the sensor's own
seeded generator, drawn in a fixed order (three normals per fix, then two for the wandering
bias if it has one, then one uniform if outages can happen), so a run is reproducible; with
no wandering bias and no outages the draws are exactly those of the white-noise model.
"""

from __future__ import annotations

import math

import numpy as np

from world.core.rates import GNSS, Rate
from world.ego.body import EgoTruth
from world.frames import GnssFix, wrap_angle
from world.sensors.sensor import Reading
from world.spec import GnssSpec


class GnssSensor:
    """A GNSS receiver on the car (module doc); it keeps its wandering bias and outage."""

    def __init__(self, spec: GnssSpec, rng: np.random.Generator) -> None:
        self.spec = spec
        self.rng = rng
        self.wander = (spec.bias_sigma * rng.normal(0.0, 1.0, 2) if spec.bias_sigma > 0.0
                       else np.zeros(2))  # [m] (2,) the wandering bias now, map frame
        self.outage = False  # no fix now
        self._t: float | None = None  # [s] time of the last fix

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

    def heading_sigma(self, speed: float) -> float:
        """[rad] 1-sigma of the heading at ``speed`` [m/s]."""
        s = self.spec
        if s.velocity_sigma <= 0.0:
            return s.heading_sigma
        return math.hypot(s.heading_sigma, math.atan2(s.velocity_sigma, abs(speed)))

    def measure(self, t: float, truth: EgoTruth) -> GnssFix:
        """The fix at ``t`` [s] of the car in its true state ``truth``."""
        s = self.spec
        noise = self.rng.normal(0.0, 1.0, 3)
        dt = 0.0 if self._t is None else max(t - self._t, 0.0)
        self._t = t
        self._advance(dt)
        heading_sigma = self.heading_sigma(truth.speed)
        if self.outage:
            return GnssFix(t=t, x=math.nan, y=math.nan, heading=math.nan,
                           sigma=s.stated_sigma, heading_sigma=heading_sigma, valid=False)
        heading = truth.yaw + heading_sigma * noise[2]
        return GnssFix(
            t=t,
            x=float(truth.position[0] + s.bias[0] + self.wander[0] + s.sigma * noise[0]),
            y=float(truth.position[1] + s.bias[1] + self.wander[1] + s.sigma * noise[1]),
            heading=wrap_angle(heading),
            sigma=s.stated_sigma,
            heading_sigma=heading_sigma,
        )

    def _advance(self, dt: float) -> None:
        """Move the wandering bias and the outage state on by ``dt`` [s]."""
        s = self.spec
        if s.bias_sigma > 0.0:
            a = math.exp(-dt / s.bias_tau)
            step = self.rng.normal(0.0, 1.0, 2)
            self.wander = a * self.wander + math.sqrt(1.0 - a * a) * s.bias_sigma * step
        if s.dropout_rate > 0.0:
            u = float(self.rng.uniform())
            if self.outage:
                self.outage = u >= 1.0 - math.exp(-dt / s.dropout_duration)
            else:
                self.outage = u < 1.0 - math.exp(-s.dropout_rate * dt)
