"""Stanley lateral control with a PID on the front-axle error (ICCAS 2020, Eq. 1).

The law (ICCAS 2020 "FSM-based vehicle system", Eq. 1, after the Stanley controller of
Hoffmann, Tomlin, Montemerlo and Thrun, "Autonomous Automobile Trajectory Tracking for
Off-Road Driving", ACC 2007):

    delta = (theta_p - theta)
          + atan((kp * e_fa + ki * int(e_fa dt) + kd * de_fa/dt) / (v_x + k_soft))
          + k_ff * atan(L * kappa_p)                        (extension, off by default)
          + k_yaw * (v_x * kappa_p - yaw_rate)              (Hoffmann 2007 yaw damping)

- delta [rad] is the road-wheel angle of the bicycle model, left +; v_x [m/s] the forward
  speed (a negative one taken as 0); L [m] the wheelbase.
- theta_p [rad] is the path tangent at the point closest to the front axle and theta [rad]
  the car's heading, both in the map frame; their difference is wrapped to (-pi, pi].
  kappa_p [1/m] is the path's curvature there, > 0 turning left.
- e_fa [m] is the signed distance from the front axle centre to the path, > 0 when the front
  axle is to the RIGHT of the path, so that a positive (left) steer corrects it.
- k_soft [m/s] (Hoffmann's softening constant) is added to the speed: the plain law's
  cross-track gain kp / v_x grows without bound as v_x -> 0, so a car at a crawl would slam
  the wheel to the stop and over-steer as soon as it rolls. With k_soft the gain is at most
  kp / k_soft.
- Curvature feed-forward k_ff * atan(L * kappa_p): an extension to Eq. 1, off (k_ff = 0) on
  purpose. Because theta_p is taken at the FRONT axle, the heading term already carries the
  whole kinematic steady-state steer on an arc: a car turning about O with its front axle on
  the circle has its front wheel pointing along the circle's tangent there, so theta_p -
  theta = delta_ss = atan(L / R_rear) exactly. Adding atan(L kappa) on top counts the arc
  twice and leaves a steady offset e_fa ~ -(v + k_soft) L kappa / kp that the integrator
  must then work off (tests/control/test_closed_loop.py shows both). k_ff = 1 suits only a
  formulation whose heading term does not carry the arc (e.g. theta_p taken at the rear
  axle); understeer at speed is left to the integrator.
- k_yaw [s] damps the yaw rate against the path's, v_x * kappa_p (Hoffmann 2007).

The result is clamped to +-``max_steer`` and rate limited to ``max_steer_rate``.
Anti-windup: the integral term is clamped (``integral_limit``), frozen below
``min_integration_speed`` (a car at rest cannot reduce its error), and frozen while the
previous command was limited in the direction the error pushes.

Gains (checked by tests/control/test_closed_loop.py on a kinematic bicycle with a steering
lag): with this law the front axle moves sideways at -v sin(atan(u / (v + k_soft))), u the
numerator, so e_fa decays as a first-order system at a rate of about kp v / (v + k_soft).
kp sets that rate (Hoffmann's k). kd is 0: e_fa is already first order in the kinematic
loop, and a derivative only slows its decay (the term stays for Eq. 1 and a real car). ki is
small: an integrator charged by a large initial error overshoots and then decays slowly, and
its job is a small bias such as tyre slip. k_yaw damps the error on entering an arc. k_soft
is small against cruising speeds, where the gain stays near the plain law's.

Two pieces: `front_axle_error` is pure (projection of the front axle onto the path polyline;
it returns the segment index for the caller to keep as the next search hint), and
`StanleyPid` holds the state (PID integrator and derivative, previous steer).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from control.pid import Pid, PidParams
from planner.messages import ReferencePath
from world.frames import wrap_angle

__all__ = [
    "FrontAxleError",
    "StanleyParams",
    "StanleyPid",
    "front_axle_error",
]

SEARCH_BEHIND = 5  # [-] segments searched behind the hint (the car may be re-localised back)
SEARCH_AHEAD = 100  # [-] segments searched ahead of the hint


@dataclass(frozen=True, slots=True)
class FrontAxleError:
    """The front axle centre against the path (map frame)."""

    index: int  # [-] path segment (xy[index] -> xy[index + 1]) holding the closest point
    e_fa: float  # [m] signed distance to the path, > 0 when the front axle is RIGHT of it
    theta_p: float  # [rad] path tangent at the closest point, in (-pi, pi]
    curvature: float  # [1/m] path curvature at the closest point, > 0 turns left


@dataclass(frozen=True, slots=True)
class _SegmentMatch:
    index: int  # [-] segment xy[index] -> xy[index + 1]
    t: float  # [-] foot point parameter along it (outside [0, 1] only past the path's ends)
    e_right: float  # [m] signed distance of the point from the path, > 0 on its right


def _closest_on_segments(
    xy: NDArray[np.float64], point: NDArray[np.float64], lo: int, hi: int
) -> _SegmentMatch:
    """The closest of segments lo .. hi - 1 of the (N, 2) polyline `xy` to `point` [m].

    Feet are clamped to each segment, except that the path's first and last segments extend
    as lines beyond its ends.
    """
    start = xy[lo:hi]
    delta = xy[lo + 1 : hi + 1] - start
    length2 = np.einsum("ij,ij->i", delta, delta)
    rel = point - start
    dot = np.einsum("ij,ij->i", rel, delta)
    t = np.divide(dot, length2, out=np.zeros_like(dot), where=length2 > 0.0)
    t_min = np.zeros_like(t)
    t_max = np.ones_like(t)
    if lo == 0:
        t_min[0] = -math.inf
    if hi == len(xy) - 1:
        t_max[-1] = math.inf
    t = np.clip(t, t_min, t_max)
    offset = rel - t[:, None] * delta
    k = int(np.argmin(np.einsum("ij,ij->i", offset, offset)))
    distance = math.hypot(offset[k, 0], offset[k, 1])
    cross = delta[k, 0] * offset[k, 1] - delta[k, 1] * offset[k, 0]  # > 0: point LEFT of path
    return _SegmentMatch(
        index=lo + k, t=float(t[k]), e_right=-distance if cross > 0.0 else distance
    )


def front_axle_error(
    path: ReferencePath,
    x: float,
    y: float,
    heading: float,
    wheelbase: float,
    *,
    hint_index: int | None = None,
    centre_to_front_axle: float | None = None,
) -> FrontAxleError:
    """Project the front axle centre onto the path polyline.

    x, y [m] are the car centre in the map frame and heading [rad] its yaw; the front axle
    centre is `centre_to_front_axle` [m] ahead of it (default wheelbase / 2, the axle midpoint
    being the centre). The point is projected onto each searched segment and the closest foot
    kept; the first and last segments extend as lines, so that past the path's ends the error
    is still a lateral distance.
    Heading and curvature are interpolated linearly along the chosen segment.

    With `hint_index` (the previous result's index on the same path), only segments
    [hint - SEARCH_BEHIND, hint + SEARCH_AHEAD] are searched, which keeps the match on the
    right lap of a path that comes back on itself; without it, or when the match falls on the
    window's edge (a stale hint), the whole path is searched.
    """
    n_segments = len(path.xy) - 1
    if n_segments < 1:
        raise ValueError("the path needs at least two points")
    ahead = wheelbase / 2.0 if centre_to_front_axle is None else centre_to_front_axle
    point = np.array([x + ahead * math.cos(heading), y + ahead * math.sin(heading)])

    match = None
    if hint_index is not None:
        hint = min(max(hint_index, 0), n_segments - 1)
        lo, hi = max(hint - SEARCH_BEHIND, 0), min(hint + SEARCH_AHEAD + 1, n_segments)
        match = _closest_on_segments(path.xy, point, lo, hi)
        if (match.index == lo and lo > 0) or (match.index == hi - 1 and hi < n_segments):
            match = None  # the foot is at the window's edge: the hint is stale
    if match is None:
        match = _closest_on_segments(path.xy, point, 0, n_segments)

    index = match.index
    s = min(max(match.t, 0.0), 1.0)
    h0, h1 = float(path.heading[index]), float(path.heading[index + 1])
    c0, c1 = float(path.curvature[index]), float(path.curvature[index + 1])
    return FrontAxleError(
        index=index,
        e_fa=match.e_right,
        theta_p=wrap_angle(h0 + s * wrap_angle(h1 - h0)),
        curvature=c0 + s * (c1 - c0),
    )


MAX_STEER = 0.61  # [rad] the controller's road-wheel angle limit (~35 deg)


@dataclass(frozen=True, slots=True)
class StanleyParams:
    """The car's geometry (from its `CarGeometry`), and the gains and limits of the Stanley +
    PID lateral controller."""

    wheelbase: float  # [m] rear to front axle
    centre_to_front_axle: float  # [m] car centre (the ego x, y) to front axle centre
    kp: float = 2.5  # [1/s] cross-track gain (Hoffmann 2007: k = 2.5); e_fa decays at ~kp
    ki: float = 0.1  # [1/s^2] integral gain: removes offsets the kinematics miss (tyre slip)
    kd: float = 0.0  # [-] derivative gain on de_fa/dt (e_fa is already first order, see doc)
    integral_limit: float = 0.5  # [m/s] |ki * int(e_fa)| clamp (~2.2 deg at 12 m/s)
    derivative_tau: float = 0.1  # [s] low-pass on de_fa/dt
    k_soft: float = 1.0  # [m/s] softening speed added to v_x (Hoffmann 2007)
    k_ff: float = 0.0  # [-] curvature feed-forward gain on atan(L kappa_p); see module doc
    k_yaw: float = 0.05  # [s] yaw-rate damping gain (Hoffmann 2007)
    max_steer: float = MAX_STEER  # [rad] road-wheel angle limit
    max_steer_rate: float = 0.9  # [rad/s] steering rate limit (~50 deg/s)
    min_integration_speed: float = 1.0  # [m/s] below this the integrator is frozen

    @property
    def pid(self) -> PidParams:
        """The numerator's PID: error e_fa [m], output [m/s]."""
        return PidParams.of(self)


class StanleyPid:
    """Stanley + PID steering (ICCAS 2020 Eq. 1); see the module docstring for the law."""

    def __init__(self, params: StanleyParams) -> None:
        self.params = params
        self._pid = Pid(self.params.pid)
        self._steer = 0.0  # [rad] previous command, for the rate limit
        self._excess = 0.0  # [rad] previous unlimited minus limited command

    @property
    def steering_angle(self) -> float:
        """[rad] the last command, left +."""
        return self._steer

    @property
    def integral_term(self) -> float:
        """[m/s] the integral part of the numerator, ki * int(e_fa dt)."""
        return self._pid.integral_term

    def reset(self, steering_angle: float = 0.0) -> None:
        """Clear the PID; the rate limit starts from `steering_angle` [rad]."""
        self._pid.reset()
        self._steer = steering_angle
        self._excess = 0.0

    def update(
        self, error: FrontAxleError, heading: float, speed: float, yaw_rate: float, dt: float
    ) -> float:
        """One step: steering angle [rad], left +, from the front-axle error.

        heading [rad] map frame; speed [m/s] forward (negative is treated as 0); yaw_rate
        [rad/s] counter-clockwise; dt [s] since the previous update.
        """
        p = self.params
        v = max(speed, 0.0)
        integrate = v >= p.min_integration_speed and self._excess * error.e_fa <= 0.0
        numerator = self._pid.update(error.e_fa, dt, integrate=integrate)  # [m/s]
        raw = (
            wrap_angle(error.theta_p - heading)
            + math.atan(numerator / (v + p.k_soft))
            + p.k_ff * math.atan(p.wheelbase * error.curvature)
            + p.k_yaw * (v * error.curvature - yaw_rate)
        )
        clamped = min(max(raw, -p.max_steer), p.max_steer)
        max_step = p.max_steer_rate * dt
        steer = self._steer + min(max(clamped - self._steer, -max_step), max_step)
        self._excess = raw - steer
        self._steer = steer
        return steer
