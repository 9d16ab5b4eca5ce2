"""A SynchronizeAction's speed law: the actor reaches its target when the master reaches
its own, esmini's algorithm (its `SynchronizeAction::Step`), renewed at every trigger check
of period `dt`.

Distances: the master's to its target along the route (|ds|), the actor's straight to its
target in route coordinates (hypot(ds, d offset), so that a pedestrian crossing the road
on a path counts its walk). The master's time to its target is its distance over its speed
along the route; when the master stands, the actor stops (waiting) and the law goes on
from rest in the same check (a steady state's time taken off an endless master time leaves
a finite one: the profile is chosen then). The action is done
when either is within its tolerance of its target, when either distance grows (passed),
or when the master arrives within the next check; the actor then takes the final speed (or
keeps its own) and holds it.

With a final speed vf, the actor's speed follows a profile of constant accelerations that
covers its distance s in the master's time t and ends at vf: once on the straight line of
constant acceleration (v = 2 s / t - vf) it stays on it (linear); before, it first speeds
up then slows (convex: the average needed is above (v + vf) / 2) or first slows then
speeds up (concave) with the acceleration that joins that line in time (the quadratic of
esmini's "specified final speed, alternative 1"), or, when even that would need a negative
speed, slows to a stop, waits, and starts again in time. A steady state (a distance, or a
time at vf) takes its share off both the distance and the time: the actor reaches vf that
far before its target and holds it. Without a final speed, the acceleration is the
constant one that makes the average speed s / t.

An action that starts at the storyboard's first check (`opening`) is stepped twice then,
as esmini steps it in its opening frame (a step of 0 s before any entity has moved, where
every velocity reads 0: the master stands) and again in its first step of the period,
from rest: the actor waits, and its profile is chosen against an endless master time
(concave; with a convex need the first real step finds it at the apex at once: the actor
stands for the first check and is linear from the next).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

SMALL = 1e-4  # [m], [s], [m/s] esmini's SMALL_NUMBER
LARGE = 1e10  # [s] a time to the target that never comes
STOP_DECEL = -10.0  # [m/s^2] a stop at once (the actor would pass its target too early)
ON_LINE = 0.1  # [m/s] the speed counts as on the constant acceleration line within this


class Mode(enum.Enum):
    NONE = "none"
    NON_LINEAR = "non-linear"
    LINEAR = "linear"
    STOP_IMMEDIATELY = "stop immediately"
    STOPPED = "stopped"
    WAITING = "waiting"
    STEADY_STATE = "steady state"


@dataclass(frozen=True, slots=True)
class SyncInput:
    """One check's distances and speeds."""

    dist: float  # [m] the actor to its target
    master_dist: float  # [m] the master to its target
    speed: float  # [m/s] the actor's
    master_speed: float  # [m/s] the master's towards its target
    final_speed: float | None  # [m/s] None: not given


class Synchronizer:
    """The state of one running SynchronizeAction (module doc)."""

    def __init__(self, tolerance: float, tolerance_master: float,
                 steady_distance: float | None, steady_time: float | None, *,
                 opening: bool = False) -> None:
        """`opening`: the action starts at the storyboard's first check (module doc)."""
        self.tolerance = tolerance  # [m]
        self.tolerance_master = tolerance_master  # [m]
        self.steady_distance = steady_distance  # [m]
        self.steady_time = steady_time  # [s] (turned into a distance at the final speed)
        self.mode = Mode.NONE
        self.convex = False  # the non-linear profile speeds up first
        self._last = (LARGE, LARGE)  # [m] the distances at the last check
        self.opening = opening  # its first step is preceded by esmini's opening frame

    def step(self, x: SyncInput, dt: float) -> tuple[float, bool]:
        """([m/s] the actor's speed until the next check, whether the action is done)."""
        if self.opening:
            self.opening = False
            speed, done = self._step(SyncInput(x.dist, x.master_dist, 0.0, 0.0,
                                               x.final_speed), 0.0)
            if done:
                return speed, True
            x = SyncInput(x.dist, x.master_dist, speed, x.master_speed, x.final_speed)
        return self._step(x, dt)

    def _step(self, x: SyncInput, dt: float) -> tuple[float, bool]:
        dist, master_dist = x.dist, x.master_dist
        done = (dist < self.tolerance + SMALL or master_dist < self.tolerance_master + SMALL
                or dist > self._last[0] or master_dist > self._last[1])
        self._last = (dist, master_dist)
        dist = max(dist - self.tolerance, SMALL)
        master_dist = max(master_dist - self.tolerance_master, SMALL)
        t = LARGE
        speed = x.speed
        if x.master_speed > SMALL:
            t = master_dist / x.master_speed
            done = done or t < dt
        elif self.mode is not Mode.WAITING:
            self.mode = Mode.WAITING  # the actor stops and the law goes on from rest
            speed = 0.0
        if done:
            return (x.final_speed if x.final_speed is not None else speed), True
        if x.final_speed is None:
            if t >= LARGE:
                return speed, False
            self.mode = Mode.LINEAR
            return speed + (2.0 * dist / t - 2.0 * speed) / t * dt, False
        return self._with_final_speed(speed, dist, t, x.final_speed, dt), False

    def _steady(self, dist: float, t: float, vf: float) -> tuple[float, float]:
        """(distance, time) left before the steady state, or the mode set to it."""
        ss = self.steady_distance if self.steady_distance is not None else (
            (self.steady_time or 0.0) * vf)
        if self.mode is Mode.STEADY_STATE or ss <= 0.0:
            return dist, t
        time_to_ss = ss / vf if vf > SMALL else LARGE
        if dist - ss < SMALL or t - time_to_ss < SMALL:
            self.mode = Mode.STEADY_STATE
            return dist, t
        return dist - ss, t - time_to_ss

    def _with_final_speed(self, v: float, dist: float, t: float, vf: float,
                          dt: float) -> float:
        dist, t = self._steady(dist, t, vf)
        if self.mode is Mode.STEADY_STATE:
            return vf
        if self.mode is Mode.WAITING:
            if t >= LARGE:
                return v
            self.mode = Mode.NONE
        stopping = self._stopping(v, dist, t, vf, dt)
        if stopping is not None:
            return stopping
        if self.mode is Mode.LINEAR:
            return 0.0 if t >= LARGE else max(0.0, 2.0 * dist / t - max(0.0, vf))
        if self.mode is Mode.NON_LINEAR and abs(v - (2.0 * dist / t - vf)) < ON_LINE:
            self.mode = Mode.LINEAR  # passed the apex: on the line from here on
            return v
        if self.mode is Mode.NONE:
            self.mode = Mode.NON_LINEAR
            self.convex = (vf + v) / 2.0 < dist / t
        return self._non_linear(v, dist, t, vf, dt)

    def _stopping(self, v: float, dist: float, t: float, vf: float,
                  dt: float) -> float | None:
        """The speed while it stops at once or stands (None: neither, or it starts again)."""
        if self.mode is Mode.STOP_IMMEDIATELY:
            v = v + STOP_DECEL * dt
            if v < 0.0:
                self.mode = Mode.WAITING
                return 0.0
            return v
        if self.mode is Mode.STOPPED:
            if vf > SMALL and t < 2.0 * dist / vf:
                self.mode = Mode.LINEAR
                return None
            return 0.0
        return None

    def _non_linear(self, v0: float, s: float, t: float, v1: float, dt: float) -> float:
        vx, acc = _apex(v0, s, t, v1)
        if (not self.convex and acc > 0.0) or (self.convex and acc < 0.0):
            self.mode = Mode.LINEAR  # reached the apex: keep the speed for this check
            return v0
        if vx < 0.0:  # slow to a stop, wait, start again
            t1 = 2.0 * v0 * s / (v0 * v0 + v1 * v1) if v0 * v0 + v1 * v1 > 0.0 else 0.0
            acc = -v0 / t1 if abs(t1) > SMALL else 0.0
            if t1 * v0 / 2.0 > s / 2.0:
                self.mode = Mode.STOP_IMMEDIATELY
                acc = STOP_DECEL
            if v0 + acc * dt < 0.0:
                self.mode = Mode.STOPPED
                return 0.0
        return v0 + acc * dt


def _apex(v0: float, s: float, t: float, v1: float) -> tuple[float, float]:
    """([m/s] the speed at the profile's apex, [m/s^2] the acceleration to it) of the
    two-phase profile from v0 to v1 [m/s] over s [m] in t [s] (module doc)."""
    if abs(v1 - v0) < SMALL:
        vx = (s - t / 2.0 * v0) / (t / 2.0)
        return vx, (vx - v0) / (t / 2.0)
    root = math.sqrt(2.0) * math.sqrt(max(
        0.0, 2.0 * s * s - 2.0 * (v1 + v0) * t * s + (v1 * v1 + v0 * v0) * t * t))
    x1 = -(root + 2.0 * s - 2.0 * v1 * t) / (2.0 * (v1 - v0))
    x2 = -(-root + 2.0 * s - 2.0 * v1 * t) / (2.0 * (v1 - v0))
    if 0.0 < x1 < t:
        vx = (2.0 * s - root) / (2.0 * t)
        return vx, (vx - v0) / x1
    if 0.0 < x2 < t:
        vx = (2.0 * s + root) / (2.0 * t)
        return vx, (vx - v0) / x2
    return 0.0, 0.0
