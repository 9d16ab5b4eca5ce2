"""Transitions of a scripted actor's speed or lateral offset, as OpenSCENARIO's
`TransitionDynamics` shape them, and the commands that drive an `NpcMotion` by them.

A transition moves a value from `start` to `target` over a span of time [s] or of travelled
distance [m], along a shape of the normalised progress u in [0, 1]:

- step: the target at once;
- linear: u;
- sinusoidal: (1 - cos(pi u)) / 2;
- cubic: 3 u^2 - 2 u^3.

Given by `rate`, the rate is the shape's peak rate (for a lane change, the peak lateral
speed; for a speed, the peak acceleration), so the span is |target - start| x the shape's
peak slope / rate (peak slopes 1, pi / 2 and 3 / 2). Given by `distance`, a speed change is
timed by the mean speed of the symmetric shapes, span = 2 distance / (start + target); a
lateral move runs over the distance travelled. esmini times a speed change by distance the
same way; it reads a lateral `rate` as the peak lateral speed as well.

A lane change (`LateralCommand` with `ahead`) moves the entity's reference point by
esmini's law, each step of dt from progress x: the speed v is kept over ground (the speed
at the step's start: esmini steps the lane change before a speed action of the same
step); timed
(time or rate), the lateral step is |f'(x)| dt (the shape's slope before the step), the
progress along the lane sqrt((v dt)^2 - (f'(x) dt)^2) and x advances by dt (a lateral step
longer than v dt: no progress along, x advances by v dt on the linear shape); by distance,
the progress along the lane is v dt / sqrt(1 + f'(x)^2) and x advances by it. The body's
heading from its lane's direction is the step's direction, atan2(lateral, along); 0 once
the change is done.

Commands (a director gives them: `avsim.run.storyboard`) override the actor's own scripted
actions while they run; each carries a `tag` that the motion reports in `finished` once the
command reached its goal.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass


class Shape(enum.Enum):
    STEP = "step"
    LINEAR = "linear"
    SINUSOIDAL = "sinusoidal"
    CUBIC = "cubic"


SPAN_TOL = 1e-9  # [s] or [m] a transition this close to its span's end is done (sums of
#   steps fall short of it by rounding)
PEAK_SLOPE = {Shape.STEP: math.inf, Shape.LINEAR: 1.0, Shape.SINUSOIDAL: 0.5 * math.pi,
              Shape.CUBIC: 1.5}  # [-] the largest d(fraction)/du of each shape


def fraction(shape: Shape, u: float) -> tuple[float, float]:
    """(fraction [0..1], its slope d fraction / du) of `shape` at progress u (clipped)."""
    u = min(max(u, 0.0), 1.0)
    if shape is Shape.STEP:
        return 1.0, 0.0
    if shape is Shape.LINEAR:
        return u, 1.0
    if shape is Shape.SINUSOIDAL:
        return 0.5 * (1.0 - math.cos(math.pi * u)), 0.5 * math.pi * math.sin(math.pi * u)
    return u * u * (3.0 - 2.0 * u), 6.0 * u * (1.0 - u)


@dataclass(frozen=True, slots=True)
class Transition:
    """A value from `start` to `target` along `shape` over `span` (time [s] or distance [m];
    0: at once)."""

    start: float
    target: float
    shape: Shape
    span: float  # [s] or [m], >= 0

    def at(self, x: float) -> tuple[float, float, bool]:
        """(value, d value / dx, done) at `x` [s] or [m] into the transition."""
        if self.span <= 0.0 or self.shape is Shape.STEP or x >= self.span - SPAN_TOL:
            return self.target, 0.0, True
        f, slope = fraction(self.shape, x / self.span)
        delta = self.target - self.start
        return self.start + delta * f, delta * slope / self.span, False


@dataclass(frozen=True, slots=True)
class LaneChangeStep:
    """One step of a lane change's reference point (module doc)."""

    x: float  # [s] or [m] the transition's progress after the step
    offset: float  # [m] the reference point's lateral offset after the step
    along: float  # [m] its progress along the lane this step (>= 0)
    heading: float  # [rad] the body's heading from the lane's direction, left +
    done: bool


HEADING_ACROSS = 0.5 * math.pi - 1e-9  # [rad] a step with no progress along points across


def lane_change_step(transition: Transition, x: float, by_distance: bool, speed: float,
                     dt: float) -> LaneChangeStep:
    """The step of dt [s] at `speed` [m/s] over ground from progress `x` along `transition`
    (of the lateral offset [m], in time [s] or, `by_distance`, in distance along [m])."""
    step_len = abs(speed) * dt
    if step_len <= 0.0:  # at rest nothing moves (esmini: no lateral motion at rest)
        offset = transition.at(x)[0] if x > 0.0 else transition.start
        return LaneChangeStep(x, offset, 0.0, 0.0, False)
    _, rate, _ = transition.at(x)
    if by_distance:
        along = step_len / math.sqrt(1.0 + rate * rate)
        offset, _, done = transition.at(x + along)
        return LaneChangeStep(x + along, offset, along, math.atan(rate), done)
    lateral = abs(rate) * dt
    if lateral < step_len:
        along = math.sqrt(step_len * step_len - lateral * lateral)
        offset, _, done = transition.at(x + dt)
        return LaneChangeStep(x + dt, offset, along,
                              math.atan2(math.copysign(lateral, rate), along), done)
    # faster across than the speed allows: straight across, linearly, at the speed
    change = abs(transition.target - transition.start)
    x_new = x + step_len * transition.span / change
    linear = Transition(transition.start, transition.target, Shape.LINEAR, transition.span)
    offset, _, done = linear.at(x_new)
    return LaneChangeStep(x_new, offset, 0.0, math.copysign(HEADING_ACROSS, rate), done)


def span_by_rate(shape: Shape, change: float, rate: float) -> float:
    """[s] the span of a change of |change| whose peak rate is `rate` (> 0)."""
    if shape is Shape.STEP or change == 0.0:
        return 0.0
    return abs(change) * PEAK_SLOPE[shape] / rate


def speed_span_by_distance(start: float, target: float, distance: float) -> float:
    """[s] the time a speed change from `start` to `target` [m/s] takes over `distance` [m]
    (the symmetric shapes' mean speed is the two ends' mean)."""
    mean = 0.5 * (start + target)
    if mean <= 0.0:
        raise ValueError("a speed change by distance needs a positive mean speed")
    return distance / mean


@dataclass(frozen=True, slots=True)
class SpeedCommand:
    """Drive the speed along `transition` (in time) from `t0` [s], then hold its target."""

    tag: str
    transition: Transition
    t0: float  # [s]
    continuous: bool = False  # never reports finished (it ends when it is stopped)


@dataclass(frozen=True, slots=True)
class TrackCommand:
    """Drive the speed towards `target` [m/s] within the acceleration limits, every step
    (a director refreshes the target: a gap to keep, a speed to follow)."""

    tag: str
    target: float  # [m/s]
    max_accel: float  # [m/s^2] > 0
    max_decel: float  # [m/s^2] > 0
    max_speed: float = math.inf  # [m/s]


@dataclass(frozen=True, slots=True)
class LateralCommand:
    """Move the lateral offset along `transition` (in time from `t0` [s], or in travelled
    distance from station `s0` [m] when `by_distance`)."""

    tag: str
    transition: Transition  # of the offset from the route's reference line [m]
    t0: float  # [s]
    s0: float  # [m] the station when it started (travelled distance = |s - s0|)
    by_distance: bool = False
    lane: int | None = None  # the lane it ends in (a lane change), None: unchanged
    ahead: float | None = None  # [m] a lane change: the transition moves the reference
    #   point, this far behind the body centre, by esmini's law (module doc); None: it moves
    #   the body centre at the full speed along the route


@dataclass(frozen=True, slots=True)
class PathCommand:
    """Follow a polyline in route coordinates: stations [m], offsets [m] and, when timed,
    the times [s] each vertex is reached (else at the speed held when it started)."""

    tag: str
    s: tuple[float, ...]  # [m]
    offset: tuple[float, ...]  # [m]
    times: tuple[float, ...] | None  # [s] simulation time at each vertex, increasing
    lane: int | None = None  # the lane its end is in (None: unchanged)

    def speeds_at_end(self, speed: float) -> tuple[float, float]:
        """([m/s] along the route, [m/s] over ground) of the path's last segment (timed: its
        own; untimed: `speed` [m/s] along it). An actor goes on along its lane at the speed
        over ground once the path ends, as esmini's entities move on along the road at the
        speed the trajectory gave them."""
        ds = self.s[-1] - self.s[-2] if len(self.s) > 1 else 0.0
        do = self.offset[-1] - self.offset[-2] if len(self.s) > 1 else 0.0
        length = math.hypot(ds, do)
        if self.times is not None and len(self.times) > 1:
            span = max(self.times[-1] - self.times[-2], 1e-9)
            return ds / span, length / span
        return (speed * ds / length, abs(speed)) if length > 0.0 else (0.0, 0.0)

    def velocity(self, t: float, s: float, offset: float, speed: float, dt: float,
                 index: int) -> tuple[float, float, bool, int]:
        """([m/s] along the route, [m/s] across, done, the vertex headed for) to follow the
        path this step from (s, offset) at time t: timed, towards the point due at t + dt;
        untimed, at `speed` towards vertex `index` (the next one once within a step)."""
        if self.times is not None:
            return (*self._timed(t, s, offset, dt), index)
        return self._untimed(s, offset, speed, dt, index)

    def _timed(self, t: float, s: float, offset: float,
               dt: float) -> tuple[float, float, bool]:
        assert self.times is not None
        tn = t + dt
        if tn >= self.times[-1] - 1e-9:
            left = max(self.times[-1] - t, dt)
            return (self.s[-1] - s) / left, (self.offset[-1] - offset) / left, True
        if tn <= self.times[0]:
            return 0.0, 0.0, False
        # the point due at t + dt, on the segment that holds that time
        i = max(k for k in range(len(self.times) - 1) if self.times[k] <= tn)
        u = (tn - self.times[i]) / (self.times[i + 1] - self.times[i])
        sn = self.s[i] + u * (self.s[i + 1] - self.s[i])
        on = self.offset[i] + u * (self.offset[i + 1] - self.offset[i])
        return (sn - s) / dt, (on - offset) / dt, False

    def _untimed(self, s: float, offset: float, speed: float, dt: float,
                 index: int) -> tuple[float, float, bool, int]:
        reach = max(abs(speed) * dt, 1e-6)
        while index < len(self.s):
            ds, do = self.s[index] - s, self.offset[index] - offset
            dist = math.hypot(ds, do)
            if dist > reach:
                return speed * ds / dist, speed * do / dist, False, index
            index += 1
        return (self.s[-1] - s) / dt, (self.offset[-1] - offset) / dt, True, index


@dataclass(frozen=True, slots=True)
class ProfileCommand:
    """Drive the speed through the points (`times` [s] simulation time, `speeds` [m/s]),
    linearly between them, then hold the last speed; done at the last time."""

    tag: str
    times: tuple[float, ...]  # [s] increasing (equal neighbours: a step)
    speeds: tuple[float, ...]  # [m/s]

    def at(self, t: float) -> tuple[float, bool]:
        """([m/s] the speed at t [s], whether the profile is done)."""
        if t >= self.times[-1] - SPAN_TOL:
            return self.speeds[-1], True
        if t <= self.times[0]:
            return self.speeds[0], False
        i = max(k for k in range(len(self.times) - 1) if self.times[k] <= t)
        span = self.times[i + 1] - self.times[i]
        u = (t - self.times[i]) / span if span > 0.0 else 1.0
        return self.speeds[i] + u * (self.speeds[i + 1] - self.speeds[i]), False


@dataclass(frozen=True, slots=True)
class TeleportCommand:
    """Put the actor's centre at station `s` [m], offset `offset` [m] (lane `lane`) at once;
    it keeps its speed."""

    tag: str
    s: float  # [m]
    offset: float  # [m] from the route's reference line, left +
    lane: int | None  # the lane it is in now (None: unchanged)
