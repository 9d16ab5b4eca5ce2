"""The car's own pose estimate: an EKF fusing GNSS fixes, wheel odometry and the gyro, and
the camera's lane on the HD map (map matching).

State (map frame, car centre): ``[x, y, heading, speed, yaw_rate, bias_x, bias_y]`` in
``[m, m, rad, m/s, rad/s, m, m]``, heading counter-clockwise from +x, wrapped to (-pi, pi];
``bias_*`` is the GNSS receiver's slowly wandering error (a fix measures position + bias).

Steps:

1. The first valid GNSS fix initialises the state (speed and yaw rate from the latest
   odometry sample, if one came before it, else zero with ``init_*_sigma``; the bias zero
   with its assumed sigma (step 2), so that position + bias is known to the white noise).
   Odometry before that is only remembered.
2. Predict to every sample's time with a unicycle model evaluated at the midpoint heading
   (``x += v dt cos(psi + w dt / 2)``, ...): it matches the exact constant-turn-rate (CTRV)
   chord up to a relative length error of ``(w dt)^2 / 24``, negligible at odometry rates,
   and its Jacobian has no ``w -> 0`` singularity. The wheels' speed is the rear axle's, so
   the car's centre, ``rear_axle`` ahead of it, also moves sideways by ``rear_axle x w dt``
   (`motion`): through a junction's turn, where the camera sees no line, the pose is this
   dead reckoning. Process noise: white longitudinal and yaw
   acceleration (``accel_sigma``, ``yaw_accel_sigma``) plus a random walk on position and
   heading (``position_walk``, ``heading_walk``: slip, tyre radius error). The bias is a
   first-order Gauss-Markov process (``gnss_bias_tau``) of 1-sigma the receiver's stated
   accuracy, with a map at least ``gnss_bias_floor``: a receiver may be off by more than it
   says, and the camera's lane must be able to correct that. A receiver that states
   carrier-phase (RTK) accuracy (``rtk_sigma`` or better) is taken at its word: the camera's
   lane errors would otherwise pass into the bias estimate and move the car's pose where
   nothing corrects it (through a town junction's turn, out of its corridor by 0.35 m).
   Its word holds only while it agrees with the camera's lane: every confident lane estimate
   is compared with the fix of its time across the matched lane (`LaneMatch.fix_offset`;
   not where they are half a lane or more apart: the camera may then have matched the lane
   beside, whose lines look alike, and the fix is what tells), and where
   `perception.health` finds them apart for long (`gnss_consistent`), the receiver is
   assumed off by what they disagree by, at least the floor: the bias's variance is opened
   to that (and the position's with it, their sum, what the fix measures, kept), so
   that the camera's lane passes its gate and pins the position across the lane while the
   fixes move only the bias; along the route the station stays the odometry's.
3. Update at every odometry sample with its speed (mean rear wheel spin x nominal radius;
   while a wheel locks under hard braking, reading ``wheel_lock_ratio`` or more below the
   fastest one, the fastest wheel's: the reference speed of an ABS, `wheel_speed`) and the
   gyro yaw rate, and at every valid GNSS fix with position + bias and heading (the
   white noise ``gnss_white`` x the fix's stated sigma, at least ``gnss_sigma``; the heading
   noise the larger of the fix's own and ``gnss_heading_sigma``); an invalid fix (an
   outage) is skipped. The heading innovation is wrapped to (-pi, pi].
4. Map matching (`on_lane`): a camera lane estimate gives the car's lateral offset from a
   lane centre and its heading relative to the lane: a confident one (``lane_confidence``),
   or a less confident one (down to ``weak_lane_confidence``: one line and the lane's width,
   a truck beside hiding the other) whose frame's detection the lane filter took, its noise
   scaled up by ``lane_confidence`` / confidence. The lane is the HD map's
   ego-direction lane that puts the car nearest the estimate (before the first match: the
   lane the car starts in, since a GNSS bias may exceed half a lane). The first match is
   not gated by the receiver's accuracy: the car is in its start lane, wherever the first fix
   put it (a bias the receiver does not state, 4.6 m across under a degraded receiver, is
   beyond the gate of a bias of 1 m 1-sigma, and the car would steer out of its lane to
   bring the biased estimate into it): where the gate rejects it, the bias's variance
   across the car is opened to the innovation's square (the position's with it, their sum
   kept: `gnss_consistent`) and it is applied; not against a receiver stating RTK
   accuracy, which is taken at its word until `perception.health` finds it off.
   The pseudo-measurement
   is the estimate projected onto that lane (its station kept) with the camera's lateral
   offset and heading in place of its own; the innovation is taken against the pose the
   stack had at the frame's time (the frame arrives late) and applied now. It is gated by
   its Mahalanobis distance (``lane_gate``), so a reading that would put the car in another
   place than the estimate allows (a wrong lane, a misdetection) is rejected.
5. Along the route: at a town junction the painted lines end at its mouth (`on_line_end`),
   and before a stop sign or a town junction a stop line is painted across the lane
   (`on_stop_line`, seen by `perception.stop_lines`); where the camera sees either, the car's
   station is the map's less that distance (gated likewise; a stop line, unambiguous within
   its window, first raises the variance along the route to its innovation's square).

So the camera pins the lateral position and heading while it sees the lane; the station
along the route comes from the odometry (the map's stations of the dead-reckoned pose) and,
where the map has them, from stop lines and the ends of the lines at a town junction; GNSS
only bounds the drift through the bias's mean reversion. Without the camera, a GNSS
bias cannot be separated from the position: the estimate follows the biased fixes.

The filter's update step is filterpy's `ExtendedKalmanFilter.update` (Joseph form) with our
own Jacobians; the prediction and the gated map-matching update are done here.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter
from numpy.typing import NDArray

from perception.messages import EgoState, LaneEstimate, Track
from world.frames import GnssFix, Odometry, wrap_angle
from world.hdmap import Lane, RoadMap, StopSign

FloatArray = NDArray[np.float64]

DIM_X = 7
IX, IY, IPSI, IV, IW, IBX, IBY = range(DIM_X)
DEG = math.pi / 180.0  # [rad/deg]
FIXES_KEPT = 4  # the last fused fixes kept to compare a camera frame (one period late) with

_H_GNSS = np.eye(DIM_X)[[IX, IY, IPSI]] + np.eye(DIM_X)[[IBX, IBY, IPSI]] * [[1], [1], [0]]
#   (3, 7): position + bias, heading
_H_ODO = np.eye(DIM_X)[[IV, IW]]  # (2, 7) speed, yaw rate


class NotInitialisedError(RuntimeError):
    """The localizer has not received its first GNSS fix yet."""


@dataclass(frozen=True, slots=True)
class LocalizerParams:
    """Measurement and process noise (1-sigma) of the localization EKF."""

    gnss_sigma: float = 0.05  # [m] white position noise floor of a fix
    gnss_white: float = 0.25  # [-] the white part of a fix's stated sigma (the rest wanders)
    gnss_heading_sigma: float = 0.2 * DEG  # [rad] heading noise floor; the fix's larger wins
    gnss_bias_tau: float = 60.0  # [s] correlation time assumed for the GNSS bias
    rtk_sigma: float = 0.1  # [m] a receiver stating this or better has a carrier-phase fix
    #   (RTK): its accuracy is taken as stated, no floor
    gnss_bias_floor: float = 1.0  # [m] 1-sigma of the bias assumed of any receiver, however
    #   accurate it says it is (an offset it does not know of: lever arm, datum, a constant
    #   error); the camera's lane may move the position across the lane this far
    wheel_speed_sigma: float = 0.05  # [m/s] odometry speed noise
    gyro_sigma: float = 0.005  # [rad/s] gyro yaw-rate noise
    accel_sigma: float = 3.0  # [m/s^2] white longitudinal acceleration (process)
    yaw_accel_sigma: float = 1.0  # [rad/s^2] white yaw acceleration (process)
    rear_axle: float = 0.0  # [m] the estimated point (the car's centre) ahead of the rear
    #   axle, whose mid-point moves along the heading at the rear wheels' speed (`motion`)
    position_walk: float = 0.02  # [m/sqrt(s)] position random walk (slip, radius error)
    heading_walk: float = 0.001  # [rad/sqrt(s)] heading random walk (gyro/heading slip)
    init_speed_sigma: float = 1.0  # [m/s] initial speed uncertainty (no odometry before fix)
    init_yaw_rate_sigma: float = 0.1  # [rad/s] initial yaw-rate uncertainty, as above
    lane_offset_sigma: float = 0.15  # [m] camera lane offset noise (its frames' errors are
    #   correlated: about 4 x the 0.04 m RMS error measured on normal_driving)
    lane_heading_sigma: float = 1.0 * DEG  # [rad] camera heading-to-lane noise (0.66 deg RMS)
    lane_confidence: float = 0.5  # [-] a lane estimate this confident is a measurement
    weak_lane_confidence: float = 0.2  # [-] less confident, down to this, it is one only when
    #   this frame's detection was taken (`LaneEstimate.age` 0), its noise scaled by
    #   `lane_confidence` / confidence: a lane kept on one line beside a truck for minutes
    #   (ALKS 4.1.3) still pins the position across the lane, or a consumer receiver's
    #   wandering bias carries the pose a metre off the lane the camera keeps
    wheel_lock_ratio: float = 0.5  # [-] a wheel spinning this much slower than the fastest
    #   is locking (braking): the speed is then the fastest wheel's (`wheel_speed`); in the
    #   tightest turn a car makes (5 m at the rear axle) the inner rear wheel turns 35 %
    #   slower than the outer front one, and that is no lock
    lane_gate: float = 13.8  # [-] Mahalanobis distance^2 gate (chi^2, 2 dof, 99.9 %)
    line_end_sigma: float = 1.0  # [m] where the camera sees the painted lines end
    line_end_range: tuple[float, float] = (10.0, 28.0)  # [m] ahead of the car's centre where
    #   a line end is believed: well inside the bird's-eye view (5 .. 35 m), not cut by it
    line_end_clear: float = 3.0  # [m] a line ending this near a car ahead's rear, or beyond
    #   it, may end where that car hides it (the line's end seen moves with the car)
    line_end_gate: float = 10.8  # [-] Mahalanobis distance^2 gate (chi^2, 1 dof, 99.9 %),
    #   also of a stop line's
    stop_line_sigma: float = 0.3  # [m] where the camera sees a stop line's near edge
    stop_line_window: float = 2.0  # [m] a stop line seen is the map's nearest within 3 x this


@dataclass(frozen=True, slots=True)
class LaneMatch:
    """What one map-matching update did."""

    lane: int  # the map lane the camera's lane was matched with (-1: along the route)
    innovation: tuple[float, float]  # [m, rad] lateral offset, heading: camera minus pose
    #   (along the route: [m] station, 0)
    distance2: float  # [-] its squared Mahalanobis distance
    accepted: bool  # within the gate, applied
    correction: tuple[float, float, float]  # [m, m, rad] x, y, heading added to the state
    fix_offset: float = math.nan  # [m] the fix nearest the frame's time, its offset across
    #   the matched lane less the camera's (left +; NaN: no fix, or a lane not confident)
    fix_sigma: float = math.nan  # [m] the 1-sigma accuracy that fix states


def wheel_speed(odo: Odometry, lock_ratio: float) -> float:
    """[m/s] the car's speed from its wheels: the mean rear-wheel spin (`Odometry.speed`),
    unless a wheel spins ``lock_ratio`` or more slower than the fastest (a locking wheel
    under hard braking reads far below the ground speed, a locked one 0): then the fastest
    wheel's, the one slipping least (an ABS's reference speed). The spin differences of a
    turn (inner wheels slower) or a flat tyre's smaller radius stay below the ratio."""
    spins = odo.wheel_speeds
    fastest = max(spins)
    if fastest > 0.0 and min(spins) < (1.0 - lock_ratio) * fastest:
        return fastest * odo.wheel_radius
    return odo.speed


def clear_ahead(tracks: Sequence[Track], half_width: float) -> float:
    """[m] how far ahead of the car's centre its lane is free: the nearest rear of a tracked
    object ahead whose box reaches within ``half_width`` [m] of the car's centre line
    (vehicle frame at each track's time); infinity when none."""
    rears = [t.rel_x - 0.5 * t.length for t in tracks
             if t.rel_x > 0.0 and abs(t.rel_y) < half_width + 0.5 * t.width]
    return min(rears, default=math.inf)


def motion(x: FloatArray, dt: float, lever: float = 0.0) -> tuple[FloatArray, FloatArray]:
    """Propagate state ``x`` by ``dt`` [s]; return (x', F) with F its Jacobian. The pose
    moves, the rest (and any bias states after the first five) stays.

    The speed is the rear axle's (its mid-point moves along the heading, no slip); the
    state's point is ``lever`` [m] ahead of it, so it also moves sideways by
    ``lever x yaw rate``: ``p += v dt u(a) + lever w dt n(a)`` with ``u`` the unit vector
    of the midpoint heading ``a`` and ``n`` its left normal. Without that term a turn
    through an angle ``phi`` leaves the point ``2 lever sin(phi / 2)`` off (a town's 90 deg
    turn 1.9 m for the car's centre 1.35 m ahead of its rear axle, a U-turn 2.7 m)."""
    psi, v, w = x[IPSI], x[IV], x[IW]
    a = psi + 0.5 * w * dt  # [rad] midpoint heading
    c, s = math.cos(a), math.sin(a)
    side = lever * w * dt  # [m] sideways, left +
    out = x.copy()
    out[IX] += v * dt * c - side * s
    out[IY] += v * dt * s + side * c
    out[IPSI] = wrap_angle(psi + w * dt)
    f = np.eye(len(x))
    f[IX, IPSI] = -v * dt * s - side * c
    f[IX, IV] = dt * c
    f[IX, IW] = -0.5 * v * dt * dt * s - lever * dt * s - 0.5 * side * dt * c
    f[IY, IPSI] = v * dt * c - side * s
    f[IY, IV] = dt * s
    f[IY, IW] = 0.5 * v * dt * dt * c + lever * dt * c - 0.5 * side * dt * s
    f[IPSI, IW] = dt
    return out, f


def process_noise(x: FloatArray, dt: float, p: LocalizerParams) -> FloatArray:
    """(7, 7) discrete process noise of the pose and motion for a step of ``dt`` [s] from
    state ``x`` (the bias's is added by the filter, which knows its sigma)."""
    a = x[IPSI] + 0.5 * x[IW] * dt
    half_dt2 = 0.5 * dt * dt
    g = np.zeros((DIM_X, 2))
    g[IX, 0] = half_dt2 * math.cos(a)
    g[IY, 0] = half_dt2 * math.sin(a)
    g[IPSI, 1] = half_dt2
    g[IV, 0] = dt
    g[IW, 1] = dt
    q: FloatArray = (g * [p.accel_sigma**2, p.yaw_accel_sigma**2]) @ g.T
    q[IX, IX] += p.position_walk**2 * dt
    q[IY, IY] += p.position_walk**2 * dt
    q[IPSI, IPSI] += p.heading_walk**2 * dt
    return q


def _largest_eigenvalue(a: float, b: float, c: float) -> float:
    """The larger eigenvalue of the symmetric 2 x 2 matrix [[a, b], [b, c]] (closed form)."""
    return float(0.5 * (a + c) + math.hypot(0.5 * (a - c), b))


def _gnss_residual(z: FloatArray, hx: FloatArray) -> FloatArray:
    y = z - hx
    y[2] = wrap_angle(float(y[2]))
    return y


def _h_gnss(_x: FloatArray) -> FloatArray:
    return _H_GNSS


def _hx_gnss(x: FloatArray) -> FloatArray:
    return np.array([x[IX] + x[IBX], x[IY] + x[IBY], x[IPSI]])


def _h_odo(_x: FloatArray) -> FloatArray:
    return _H_ODO


def _hx_odo(x: FloatArray) -> FloatArray:
    return x[[IV, IW]]


class Localizer:
    """EKF pose estimate from `GnssFix` and `Odometry` samples and, given the HD map, the
    camera's lane (`on_lane`); see the module docstring."""

    def __init__(self, params: LocalizerParams | None = None, road: RoadMap | None = None,
                 start_lane: int = 0) -> None:
        """`road`: the HD map the camera's lane is matched on (None: no map matching);
        `start_lane`: the ego-direction lane the car starts in."""
        self.params = params if params is not None else LocalizerParams()
        p = self.params
        self.road = road
        self.start_lane = start_lane
        self._r_odo = np.diag([p.wheel_speed_sigma**2, p.gyro_sigma**2])  # (2, 2) constant
        self._r_lane = np.diag([p.lane_offset_sigma**2, p.lane_heading_sigma**2])
        self.reset()

    def reset(self) -> None:
        """Forget everything; the next GNSS fix initialises again."""
        self._ekf = ExtendedKalmanFilter(dim_x=DIM_X, dim_z=3)
        self._t = 0.0  # [s] time the filter state refers to
        self._initialised = False
        self._last_odo: Odometry | None = None
        self._bias_sigma = 0.0  # [m] 1-sigma of the GNSS bias (the receiver's stated)
        self._station: float | None = 0.0  # [m] the estimate's station on the route when
        #   last placed on it (`_on_route`; first: the route's start, where the car begins)
        self.matched = False  # a camera lane has been matched on the map since the start
        self._fixes: deque[GnssFix] = deque(maxlen=FIXES_KEPT)  # the last fused fixes
        self._fix_offset = 0.0  # [m] the last `LaneMatch.fix_offset` measured
        self.gnss_trusted = True  # the receiver's stated accuracy is believed (`gnss_consistent`)

    @property
    def initialised(self) -> bool:
        return self._initialised

    @property
    def state(self) -> FloatArray:
        """(7,) copy of ``[x, y, heading, speed, yaw_rate, bias_x, bias_y]`` at the last
        sample's time."""
        return np.array(self._ekf.x, dtype=np.float64)

    @property
    def covariance(self) -> FloatArray:
        """(7, 7) copy of the state covariance, same order and units as `state`."""
        return np.array(self._ekf.P, dtype=np.float64)

    def on_odometry(self, odo: Odometry) -> None:
        """Predict to ``odo.t`` and update with its speed and yaw rate."""
        self._last_odo = odo
        if not self._initialised:
            return
        self._predict_to(odo.t)
        speed = wheel_speed(odo, self.params.wheel_lock_ratio)
        self._ekf.update(np.array([speed, odo.yaw_rate]), _h_odo, _hx_odo, R=self._r_odo)

    def on_gnss(self, fix: GnssFix) -> None:
        """Initialise from the first valid fix; later, predict to ``fix.t`` and update with
        it. A fix flagged invalid (an outage) carries nothing and is skipped.

        A fix older than the filter time is applied at the filter time (no retrodiction): a
        fix d [s] late is off by speed x d, so the sensor model must stamp fixes on time.
        """
        if not fix.valid:
            return
        if not self._initialised:
            self._initialise(fix)
            return
        self._fixes.append(fix)
        self._bias_sigma = self._bias_sigma_of(fix)
        self._predict_to(fix.t)
        sigma = self._white_sigma(fix)
        heading_sigma = max(self.params.gnss_heading_sigma, fix.heading_sigma)
        r = np.diag([sigma**2, sigma**2, heading_sigma**2])
        z = np.array([fix.x, fix.y, fix.heading])
        self._ekf.update(z, _h_gnss, _hx_gnss, R=r, residual=_gnss_residual)
        self._ekf.x[IPSI] = wrap_angle(float(self._ekf.x[IPSI]))

    def on_lane(self, lane: LaneEstimate, pose: EgoState) -> LaneMatch | None:
        """Map matching: correct the lateral position and heading with the camera's lane
        estimate ``lane``, taken when the stack's pose estimate was ``pose`` (module doc,
        step 4). None when there is nothing to match (no map, no fix yet, not confident,
        no ego-direction lane there); else what was done."""
        p = self.params
        if self.road is None or not self._initialised or not self._measures(lane):
            return None
        found = self._match(lane, pose)
        if found is None:
            return None
        index, map_lane, s = found
        _, r = self._on_route(np.array([pose.x, pose.y]), map_lane)
        theta = float(map_lane.heading_at(s))
        nu = np.array([lane.offset - float(r),
                       wrap_angle(lane.heading_error - wrap_angle(pose.heading - theta))])
        now_theta = float(map_lane.heading_at(
            self._on_route(self.state[[IX, IY]], map_lane)[0]))
        h = np.zeros((2, DIM_X))
        h[0, IX], h[0, IY] = -math.sin(now_theta), math.cos(now_theta)
        h[1, IPSI] = 1.0
        weight = min(1.0, lane.confidence / p.lane_confidence)
        match = self._gated_update(h, nu, self._r_lane / weight**2, p.lane_gate, index)
        if not match.accepted and not self.matched and self._bias_sigma > p.rtk_sigma:
            #   in the start lane, however far off the fix says (module doc)
            self._open_across(abs(float(nu[0])))
            match = self._gated_update(h, nu, self._r_lane / weight**2, p.lane_gate, index)
        self.matched = self.matched or match.accepted
        if lane.confidence < p.lane_confidence or not self._fixes:
            return match
        fix = min(self._fixes, key=lambda f: abs(f.t - lane.t))
        r_fix = float(map_lane.local_coordinates(np.array([fix.x, fix.y]), self._station)[1])
        if abs(r_fix - lane.offset) >= 0.5 * float(map_lane.width_at(s)):
            return match  # as far apart as a neighbouring lane: which lane the camera sees
            #   is what is in question (lines look alike), not the receiver
        self._fix_offset = r_fix - lane.offset
        return replace(match, fix_offset=self._fix_offset, fix_sigma=fix.sigma)

    def gnss_consistent(self, consistent: bool) -> None:
        """Whether the receiver agrees with the camera's lane (`perception.health`); when it
        stops agreeing, its stated accuracy is no longer believed across the car (module
        doc, step 2): the bias's variance in that direction is opened to at least the square
        of the floor and of the last disagreement, the position's by as much, their
        covariance lowered by as much (the sum x + b, what a fix measures, keeps its
        variance); along the car, where the camera cannot check the fixes, nothing changes.
        """
        if consistent == self.gnss_trusted:
            return
        self.gnss_trusted = consistent
        if consistent or not self._initialised:
            return
        self._open_across(max(self.params.gnss_bias_floor, abs(self._fix_offset)))

    def _open_across(self, sigma: float) -> None:
        """Open the bias's variance across the car to at least ``sigma``^2 [m^2], the
        position's by as much, their covariance lowered by as much: the sum x + b, what a fix
        measures, keeps its variance; along the car nothing changes."""
        n2 = self._across()
        pos, bias = [IX, IY], [IBX, IBY]
        cov = self._ekf.P.copy()
        more = n2 * max(sigma**2 - float(np.sum(n2 * cov[np.ix_(bias, bias)])), 0.0)
        cov[np.ix_(pos, pos)] += more
        cov[np.ix_(bias, bias)] += more
        cov[np.ix_(pos, bias)] -= more
        cov[np.ix_(bias, pos)] -= more
        self._ekf.P = cov

    def _measures(self, lane: LaneEstimate) -> bool:
        """Whether ``lane`` is a measurement for map matching (`LocalizerParams`)."""
        p = self.params
        return lane.confidence >= p.lane_confidence or (
            lane.age == 0.0 and lane.confidence >= p.weak_lane_confidence)

    def on_line_end(self, lane: LaneEstimate, pose: EgoState,
                    clear: float = math.inf) -> LaneMatch | None:
        """Along the route: at a town junction the painted lines end at its mouth
        (`world.hdmap.Junction.s_enter`). Where the map has a mouth within
        ``line_end_range`` ahead of ``pose`` (the pose at the frame's time) and the farthest
        painted line of ``lane`` ends within that range too, the car's station is the
        mouth's less that distance: an update of the position along the lane, gated like
        the lateral one (``line_end_gate``). ``clear`` [m] is how far ahead of the car's
        centre its lane is free (`clear_ahead`: a car ahead's rear): lines that end within
        ``line_end_clear`` of it, or beyond, end where that car hides them, not at the mouth,
        and are not believed. None when there is nothing to match; else what was done
        (``innovation``: [m] along the route, 0)."""
        p = self.params
        road = self.road
        if road is None or not road.junctions or not self._initialised \
                or lane.confidence < p.lane_confidence:
            return None
        ends = [b.x_max for b in (lane.left, lane.right) if b is not None]
        lo, hi = p.line_end_range
        if not ends or not lo <= max(ends) <= hi or max(ends) > clear - p.line_end_clear:
            return None
        x_end = max(ends)  # [m] the farthest line: a car ahead hides the nearer ends
        s = self._on_route(np.array([pose.x, pose.y]))[0]
        mouths = [j.s_enter - s for j in road.junctions if lo - 5.0 <= j.s_enter - s <= hi + 5.0]
        if not mouths:
            return None
        ahead = min(mouths, key=lambda d: abs(d - x_end))
        return self._along(ahead - x_end, p.line_end_sigma)

    def lane_width(self, pose: EgoState) -> float | None:
        """[m] the HD map's width of the ego-direction lane the car's centre is nearest at
        ``pose`` (the lane a camera frame taken there sees), None without a map or a lane
        there: the width the camera's lane keeps when one of its lines is hidden."""
        found = self._nearest_lane(pose)
        return None if found is None else float(found[0].width_at(found[1]))

    def _nearest_lane(self, pose: EgoState) -> tuple[Lane, float, float] | None:
        """The HD map's ego-direction lane nearest the car's centre at ``pose``, with the
        centre's station and offset [m] on the route; None without a map or a lane there."""
        if self.road is None:
            return None
        s, d = self._on_route(np.array([pose.x, pose.y]))
        lanes = [lane for lane in self.road.lanes if bool(lane.exists_at(s))]
        if not lanes:
            return None
        return min(lanes, key=lambda lane: abs(float(lane.offset_at(s)) - d)), s, d

    def map_lane(self, pose: EgoState, t: float) -> LaneEstimate | None:
        """The HD map's ego-direction lane nearest the car's centre at ``pose``, as a lane
        estimate of time ``t`` [s] in the vehicle frame there (offset, heading error and
        curvature of the map's lane on the pose; ``confidence`` 0 and no boundaries: it is
        not a measurement), None without a map or a lane there. Where the camera sees too
        little of the lane to be a measurement (its lines end at a junction's mouth, a car
        ahead hides them), the stop line across the lane is looked for across this one: the
        pose is pinned across the lane by the camera's earlier frames, and along the route
        it is the stop line that is to place it."""
        found = self._nearest_lane(pose)
        if found is None or self.road is None:
            return None
        nearest, s, d = found
        road = self.road
        return LaneEstimate(t=t, offset=d - float(nearest.offset_at(s)),
                            heading_error=wrap_angle(pose.heading - float(road.heading_at(s))),
                            curvature=float(road.curvature_at(s)),
                            width=float(nearest.width_at(s)), confidence=0.0, left=None,
                            right=None, lines=0)

    def stop_lines_ahead(self, pose: EgoState, near: float, far: float) -> list[float]:
        """[m] distances from ``pose`` to the map's painted stop lines (a stop sign's, a town
        junction's) between ``near`` and ``far`` ahead along the route."""
        if self.road is None:
            return []
        road = self.road
        s = self._on_route(np.array([pose.x, pose.y]))[0]
        lines = {f.s for f in road.features if isinstance(f, StopSign)}
        lines |= {j.s_stop for j in road.junctions}
        return sorted(d for d in (line - s for line in lines) if near <= d <= far)

    def on_stop_line(self, distance: float, pose: EgoState) -> LaneMatch | None:
        """Along the route: the camera saw the near edge of a stop line ``distance`` [m]
        ahead of the car's centre when the pose estimate was ``pose``; the nearest of the
        map's stop lines there gives the car's station (gated like the other updates). None
        when the map has no stop line near there."""
        p = self.params
        if not self._initialised:
            return None
        reach = 3.0 * p.stop_line_window
        lines = self.stop_lines_ahead(pose, distance - reach, distance + reach)
        if not lines:
            return None
        ahead = min(lines, key=lambda d: abs(d - distance))
        nu = ahead - distance
        # the map's stop lines are tens of metres apart, so the one within the window is the
        # one seen whatever the filter's own variance along the route says (the lateral
        # updates in curves make it overconfident): the variance along the route is raised
        # to the innovation's square first, so that the gate below passes and the update
        # moves the station by most of it
        h = self._along_row()
        p_along = float((h @ self._ekf.P @ h.T)[0, 0])
        if nu * nu > p_along:
            self._ekf.P = self._ekf.P + (nu * nu - p_along) * (h.T @ h)
        return self._along(nu, p.stop_line_sigma)

    def _along(self, nu: float, sigma: float) -> LaneMatch:
        """A gated update of the position along the route by ``nu`` [m] (a measured station
        less the pose's) of noise ``sigma`` [m]."""
        return self._gated_update(self._along_row(), np.array([nu]), np.array([[sigma**2]]),
                                  self.params.line_end_gate, -1)

    def _along_row(self) -> FloatArray:
        """(1, 7) the position's component along the route at the estimate."""
        assert self.road is not None
        road = self.road
        theta = float(road.heading_at(self._on_route(self.state[[IX, IY]])[0]))
        h = np.zeros((1, DIM_X))
        h[0, IX], h[0, IY] = math.cos(theta), math.sin(theta)
        return h

    def _gated_update(self, h: FloatArray, nu: FloatArray, r: FloatArray, gate: float,
                      lane: int) -> LaneMatch:
        """Update with innovation ``nu`` (m,) of a measurement (m, 7) ``h``, noise ``r``,
        unless its squared Mahalanobis distance exceeds ``gate``."""
        cov = self._ekf.P
        s_mat = h @ cov @ h.T + r
        d2 = float(nu @ np.linalg.solve(s_mat, nu))
        innovation = (float(nu[0]), float(nu[1]) if len(nu) > 1 else 0.0)
        if d2 > gate:
            return LaneMatch(lane, innovation, d2, False, (0.0, 0.0, 0.0))
        gain = cov @ h.T @ np.linalg.inv(s_mat)
        dx = gain @ nu
        i_kh = np.eye(DIM_X) - gain @ h
        self._ekf.P = i_kh @ cov @ i_kh.T + gain @ r @ gain.T
        self._ekf.x = self._ekf.x + dx
        self._ekf.x[IPSI] = wrap_angle(float(self._ekf.x[IPSI]))
        return LaneMatch(lane, innovation, d2, True,
                         (float(dx[IX]), float(dx[IY]), float(dx[IPSI])))

    def _on_route(self, xy: FloatArray, lane: Lane | None = None) -> tuple[float, float]:
        """(station, offset) [m] of the point `xy` on the route (on `lane`: from its centre;
        else from the reference line), near the station the car was last placed at: a town
        route that crosses itself passes a point twice (`world.hdmap.ReferenceLine.project`)."""
        assert self.road is not None
        on = lane if lane is not None else self.road
        s_arr, d_arr = on.local_coordinates(xy, self._station)
        self._station = float(s_arr)
        return self._station, float(d_arr)

    def _match(self, lane: LaneEstimate, pose: EgoState) -> tuple[int, Lane, float] | None:
        """(index, lane, station at the pose) of the ego-direction lane whose centre plus
        the camera's offset is nearest the pose (the start lane before the first match)."""
        assert self.road is not None
        road = self.road
        xy = np.array([pose.x, pose.y])
        s, d = self._on_route(xy)
        if self.matched:
            candidates = [i for i in range(len(road.lanes))
                          if bool(road.lanes[i].exists_at(s))]
        else:
            candidates = [self.start_lane] if 0 <= self.start_lane < len(road.lanes) \
                and bool(road.lanes[self.start_lane].exists_at(s)) else []
        if not candidates:
            return None
        best = min(candidates,
                   key=lambda i: abs(float(road.lanes[i].offset_at(s)) + lane.offset - d))
        return best, road.lanes[best], s

    def estimate(self, t: float) -> EgoState:
        """The estimate extrapolated (not committed) to time ``t`` [s].

        ``position_sigma`` [m] is the square root of the largest eigenvalue of the position
        covariance (the worst direction's 1-sigma). Raises `NotInitialisedError` before the
        first GNSS fix.
        """
        if not self._initialised:
            raise NotInitialisedError("no GNSS fix yet")
        dt = t - self._t
        x0 = self.state
        x, f = motion(x0, dt, self.params.rear_axle)
        cov = f @ self._ekf.P @ f.T + process_noise(x0, abs(dt), self.params)
        pos_var = _largest_eigenvalue(cov[0, 0], cov[0, 1], cov[1, 1])
        steering = self._last_odo.steering_angle if self._last_odo is not None else 0.0
        return EgoState(
            t=t,
            x=float(x[IX]),
            y=float(x[IY]),
            heading=float(x[IPSI]),
            speed=float(x[IV]),
            yaw_rate=float(x[IW]),
            steering_angle=steering,
            position_sigma=math.sqrt(max(pos_var, 0.0)),
        )

    def predicted_fix(self, t: float) -> tuple[float, float, float] | None:
        """What a fix at time ``t`` [s] should read, from the estimate extrapolated (not
        committed) to it: (x, y) [m] of position + bias, and the 1-sigma [m] of that
        prediction in its worst direction. None before the first fix. A fix farther from
        it than its gate allows is inconsistent with the odometry (`perception.health`)."""
        if not self._initialised:
            return None
        x0 = self.state
        x, f = motion(x0, t - self._t, self.params.rear_axle)
        cov = f @ self._ekf.P @ f.T + process_noise(x0, abs(t - self._t), self.params)
        h = _H_GNSS[:2]
        c = h @ cov @ h.T
        var = _largest_eigenvalue(c[0, 0], c[0, 1], c[1, 1])
        return (float(x[IX] + x[IBX]), float(x[IY] + x[IBY]), math.sqrt(max(var, 0.0)))

    def _bias_sigma_of(self, fix: GnssFix) -> float:
        """[m] 1-sigma of the bias assumed of a fix: its stated sigma, at least the floor
        when the camera's lane can be matched on a map (else nothing could correct it)."""
        p = self.params
        floor = p.gnss_bias_floor if self.road is not None and fix.sigma > p.rtk_sigma else 0.0
        return max(floor, fix.sigma)

    def _across(self) -> FloatArray:
        """(2, 2) the projection n n^T on the map-frame direction across the car (left)."""
        psi = float(self._ekf.x[IPSI])
        n = np.array([-math.sin(psi), math.cos(psi)])
        out: FloatArray = np.outer(n, n)
        return out

    def _white_sigma(self, fix: GnssFix) -> float:
        """[m] the white noise assumed of a fix: a part of its stated sigma, at least the
        floor."""
        return max(self.params.gnss_sigma, self.params.gnss_white * fix.sigma)

    def _initialise(self, fix: GnssFix) -> None:
        p = self.params
        odo = self._last_odo
        speed, yaw_rate = (odo.speed, odo.yaw_rate) if odo is not None else (0.0, 0.0)
        speed_sigma = p.wheel_speed_sigma if odo is not None else p.init_speed_sigma
        yaw_sigma = p.gyro_sigma if odo is not None else p.init_yaw_rate_sigma
        white = self._white_sigma(fix)
        heading_sigma = max(p.gnss_heading_sigma, fix.heading_sigma)
        self._bias_sigma = self._bias_sigma_of(fix)
        b2 = self._bias_sigma**2
        self._ekf.x = np.array([fix.x, fix.y, wrap_angle(fix.heading), speed, yaw_rate, 0.0,
                                0.0])
        cov = np.diag([b2 + white**2, b2 + white**2, heading_sigma**2, speed_sigma**2,
                       yaw_sigma**2, b2, b2])
        cov[IX, IBX] = cov[IBX, IX] = cov[IY, IBY] = cov[IBY, IY] = -b2  # x + b: the fix
        self._ekf.P = cov
        self._t = fix.t
        self._initialised = True

    def _predict_to(self, t: float) -> None:
        dt = t - self._t
        if dt <= 0.0:
            return
        x0 = self.state
        x, f = motion(x0, dt, self.params.rear_axle)
        decay = math.exp(-dt / self.params.gnss_bias_tau)
        x[[IBX, IBY]] *= decay
        f[IBX, IBX] = f[IBY, IBY] = decay
        q = process_noise(x0, dt, self.params)
        q[IBX, IBX] += self._bias_sigma**2 * (1.0 - decay * decay)
        q[IBY, IBY] += self._bias_sigma**2 * (1.0 - decay * decay)
        if not self.gnss_trusted and self.road is not None:  # across the car: the floor
            floor2 = max(self.params.gnss_bias_floor**2 - self._bias_sigma**2, 0.0)
            q[np.ix_([IBX, IBY], [IBX, IBY])] += self._across() * floor2 * (1.0 - decay * decay)
        self._ekf.x = x
        self._ekf.P = f @ self._ekf.P @ f.T + q
        self._t = t
