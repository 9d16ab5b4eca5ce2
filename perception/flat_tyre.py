"""Flat-tyre detection from the wheel-speed sensors (an indirect TPMS).

A flat tyre rolls on a smaller radius, so at the same ground speed it spins faster than the
others (a few per cent). This detector uses the wheel speeds only (`Odometry.wheel_speeds`,
[rad/s] FL, FR, RL, RR), with the gyro's yaw rate and the steering encoder to take the turn
out; it needs no tyre-pressure sensor.

Per odometry sample:

1. Each wheel's speed u = omega r (r the car's nominal rolling radius) [m/s] is turned into
   the body's forward speed at the centre line, which every wheel sees the same way when
   all roll true. A wheel at lateral offset y (left +, +-track/2) moves forward at
   v_x - yaw_rate y (the outer wheel of a turn runs faster), and a front wheel rolls along
   its steered heading delta_i (the Ackermann split of the measured bicycle angle), so:
   rear v_x = u + yaw_rate y, front v_x = u cos(delta_i) + yaw_rate y. The yaw term is
   (track / 2) / R of the speed on a radius R, on a tight bend as much as a flat: without it
   the outer wheels would look flat.
2. Gates (a sample outside them leaves the evidence as it is): the mean corrected speed is
   at least ``min_speed`` (below it the encoders' quantisation and the gyro's noise
   dominate), and no wheel is more than ``max_slip`` off the median of the four (a locked or
   spinning wheel, not a tyre).
3. A wheel is a candidate when its corrected speed exceeds its axle partner's by at least
   ``excess`` of the axle's mean, and the other axle's mean by at least ``cross_excess`` of
   that mean (so that a partner that slows, e.g. locking under braking, does not make the
   other wheel look flat).
4. Debounce: each wheel's evidence [s] grows by the sample interval while it is a candidate
   and shrinks by it otherwise, within [0, ``debounce``]; at ``debounce`` the tyre is
   declared flat. One noisy sample costs two, so a flat's evidence still builds, while a
   false candidate needs ``debounce`` net of them. The first wheel declared is latched: a
   flat tyre does not heal; `reset()` forgets it. A sample more than `MAX_GAP` after the
   previous one (or not after it) is skipped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from world.frames import Odometry, VehicleInfo, Wheel

WHEELS = (Wheel.FRONT_LEFT, Wheel.FRONT_RIGHT, Wheel.REAR_LEFT, Wheel.REAR_RIGHT)  # odometry order
PARTNER = (1, 0, 3, 2)  # the same axle's other wheel, by index
MAX_GAP = 0.25  # [s] a sample after a longer silence is skipped; timing restarts from it


@dataclass(frozen=True, slots=True)
class FlatTyreParams:
    """Thresholds of `FlatTyreDetector`, by step of the module docstring."""

    excess: float = 0.03  # [-] a wheel's corrected speed over its axle partner's, of their
    #   mean: 4 sigma of two encoders' difference at 0.5 % noise each, half a flat's excess
    cross_excess: float = 0.015  # [-] ... and over the other axle's mean, of that mean
    debounce: float = 0.5  # [s] net candidate time before a tyre is declared flat
    min_speed: float = 5.0  # [m/s] no evidence below this
    max_slip: float = 0.15  # [-] a wheel this far off the median: slip, not a tyre


@dataclass(frozen=True, slots=True)
class FlatTyreState:
    """A tyre the car found flat from its own wheel speeds."""

    wheel: Wheel
    t: float  # [s] sim time of the odometry sample that decided it
    excess: float  # [-] that wheel's corrected speed over its axle partner's, of their mean


def ackermann_split(delta: float, wheelbase: float, track: float) -> tuple[float, float]:
    """(left, right) road-wheel angles [rad] of a bicycle angle `delta` [rad], left +: both
    front wheels aim at one turn centre on the rear axle's line."""
    if abs(delta) < 1e-9:
        return 0.0, 0.0
    radius = wheelbase / math.tan(delta)  # [m] signed, > 0 turning left
    return (math.atan(wheelbase / (radius - track / 2)),
            math.atan(wheelbase / (radius + track / 2)))


def corrected_speeds(odometry: Odometry, track: float, wheelbase: float
                     ) -> tuple[float, float, float, float]:
    """[m/s] each wheel's speed as the body's forward speed (FL, FR, RL, RR): step 1 of the
    module docstring. All four agree when every tyre rolls true on its nominal radius."""
    r, yaw_rate = odometry.wheel_radius, odometry.yaw_rate
    left, right = ackermann_split(odometry.steering_angle, wheelbase, track)
    half = track / 2
    fl, fr, rl, rr = (w * r for w in odometry.wheel_speeds)
    return (fl * math.cos(left) + yaw_rate * half, fr * math.cos(right) - yaw_rate * half,
            rl + yaw_rate * half, rr - yaw_rate * half)


def candidates(speeds: tuple[float, ...], params: FlatTyreParams) -> tuple[bool, ...] | None:
    """Which wheels look flat in one sample of corrected speeds (steps 2 and 3), or None when
    the sample is outside the gates."""
    mean = sum(speeds) / 4
    ordered = sorted(speeds)
    median = 0.5 * (ordered[1] + ordered[2])
    if mean < params.min_speed or any(abs(u - median) > params.max_slip * median
                                      for u in speeds):
        return None
    axles = (0.5 * (speeds[0] + speeds[1]), 0.5 * (speeds[2] + speeds[3]))
    out = []
    for i, u in enumerate(speeds):
        own, other = axles[i // 2], axles[1 - i // 2]
        out.append(u - speeds[PARTNER[i]] >= params.excess * own
                   and u - other >= params.cross_excess * other)
    return tuple(out)


class FlatTyreDetector:
    """Debounced flat-tyre detection from the wheel speeds (the module docstring)."""

    def __init__(self, vehicle: VehicleInfo, params: FlatTyreParams | None = None) -> None:
        """`vehicle`: the car's track and wheelbase (the turn correction)."""
        self.vehicle = vehicle
        self.params = params or FlatTyreParams()
        self.reset()

    def reset(self) -> None:
        self._evidence = [0.0, 0.0, 0.0, 0.0]  # [s] per wheel
        self._last_t: float | None = None
        self._state: FlatTyreState | None = None

    @property
    def state(self) -> FlatTyreState | None:
        """The flat tyre found so far, None while none."""
        return self._state

    @property
    def evidence(self) -> tuple[float, ...]:
        """[s] per wheel (FL, FR, RL, RR): the debounce's net time as a candidate."""
        return tuple(self._evidence)

    def update(self, odometry: Odometry) -> FlatTyreState | None:
        """Take one odometry sample; the flat tyre found so far (latched), or None."""
        if self._state is not None:
            return self._state
        dt = 0.0 if self._last_t is None else odometry.t - self._last_t
        self._last_t = odometry.t
        if not 0.0 < dt <= MAX_GAP:
            return None
        p = self.params
        speeds = corrected_speeds(odometry, self.vehicle.track, self.vehicle.wheelbase)
        flags = candidates(speeds, p)
        if flags is None:
            return None
        for i, flag in enumerate(flags):
            self._evidence[i] = min(max(self._evidence[i] + (dt if flag else -dt), 0.0),
                                    p.debounce)
            if self._evidence[i] >= p.debounce - 1e-9 and self._state is None:
                partner = speeds[PARTNER[i]]
                excess = 2.0 * (speeds[i] - partner) / (speeds[i] + partner)
                self._state = FlatTyreState(WHEELS[i], odometry.t, excess)
        return self._state
