"""The car's own pose estimate: an EKF fusing GNSS fixes with wheel odometry and the gyro.

State (map frame, car centre): ``[x, y, heading, speed, yaw_rate]`` in ``[m, m, rad, m/s,
rad/s]``, heading counter-clockwise from +x, wrapped to (-pi, pi].

Steps:

1. The first GNSS fix initialises the state (speed and yaw rate from the latest odometry
   sample, if one came before it, else zero with ``init_*_sigma``). Odometry before that is
   only remembered.
2. Predict to every sample's time with a unicycle model evaluated at the midpoint heading
   (``x += v dt cos(psi + w dt / 2)``, ...): it matches the exact constant-turn-rate (CTRV)
   chord up to a relative length error of ``(w dt)^2 / 24``, negligible at odometry rates,
   and its Jacobian has no ``w -> 0`` singularity. Process noise: white longitudinal and yaw
   acceleration (``accel_sigma``, ``yaw_accel_sigma``) plus a random walk on position and
   heading (``position_walk``, ``heading_walk``: slip, tyre radius error).
3. Update at every odometry sample with its speed (mean rear wheel spin x nominal radius)
   and the gyro yaw rate, and at every GNSS fix with its position and heading (the noise the
   larger of the fix's own sigma and ``gnss_sigma`` / ``gnss_heading_sigma``); the heading
   innovation is wrapped to (-pi, pi].

A constant GNSS bias is NOT observable here: odometry measures only speed and yaw rate, never
absolute position, so the estimate follows the biased fixes (offset by the bias). Removing it
needs another absolute reference (map matching of camera lane lines, landmarks).

The filter's update step is filterpy's `ExtendedKalmanFilter.update` (Joseph form) with our
own Jacobians; the prediction is done here because the model is non-linear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter
from numpy.typing import NDArray

from perception.messages import EgoState
from world.frames import GnssFix, Odometry, wrap_angle

FloatArray = NDArray[np.float64]

DIM_X = 5
IX, IY, IPSI, IV, IW = range(DIM_X)
DEG = math.pi / 180.0  # [rad/deg]

_H_GNSS = np.eye(DIM_X)[[IX, IY, IPSI]]  # (3, 5) x, y, heading
_H_ODO = np.eye(DIM_X)[[IV, IW]]  # (2, 5) speed, yaw rate


class NotInitialisedError(RuntimeError):
    """The localizer has not received its first GNSS fix yet."""


@dataclass(frozen=True, slots=True)
class LocalizerParams:
    """Measurement and process noise (1-sigma) of the localization EKF."""

    gnss_sigma: float = 0.05  # [m] position noise floor; the fix's own larger sigma wins
    gnss_heading_sigma: float = 0.2 * DEG  # [rad] heading noise floor, as above
    wheel_speed_sigma: float = 0.05  # [m/s] odometry speed noise
    gyro_sigma: float = 0.005  # [rad/s] gyro yaw-rate noise
    accel_sigma: float = 3.0  # [m/s^2] white longitudinal acceleration (process)
    yaw_accel_sigma: float = 1.0  # [rad/s^2] white yaw acceleration (process)
    position_walk: float = 0.02  # [m/sqrt(s)] position random walk (slip, radius error)
    heading_walk: float = 0.001  # [rad/sqrt(s)] heading random walk (gyro/heading slip)
    init_speed_sigma: float = 1.0  # [m/s] initial speed uncertainty (no odometry before fix)
    init_yaw_rate_sigma: float = 0.1  # [rad/s] initial yaw-rate uncertainty, as above


def motion(x: FloatArray, dt: float) -> tuple[FloatArray, FloatArray]:
    """Propagate state ``x`` (5,) by ``dt`` [s]; return (x', F) with F the (5, 5) Jacobian."""
    psi, v, w = x[IPSI], x[IV], x[IW]
    a = psi + 0.5 * w * dt  # [rad] midpoint heading
    c, s = math.cos(a), math.sin(a)
    out = x.copy()
    out[IX] += v * dt * c
    out[IY] += v * dt * s
    out[IPSI] = wrap_angle(psi + w * dt)
    f = np.eye(DIM_X)
    f[IX, IPSI] = -v * dt * s
    f[IX, IV] = dt * c
    f[IX, IW] = -0.5 * v * dt * dt * s
    f[IY, IPSI] = v * dt * c
    f[IY, IV] = dt * s
    f[IY, IW] = 0.5 * v * dt * dt * c
    f[IPSI, IW] = dt
    return out, f


def process_noise(x: FloatArray, dt: float, p: LocalizerParams) -> FloatArray:
    """(5, 5) discrete process noise for a step of ``dt`` [s] from state ``x``."""
    a = x[IPSI] + 0.5 * x[IW] * dt
    half_dt2 = 0.5 * dt * dt
    g = np.array(
        [
            [half_dt2 * math.cos(a), 0.0],
            [half_dt2 * math.sin(a), 0.0],
            [0.0, half_dt2],
            [dt, 0.0],
            [0.0, dt],
        ]
    )
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
    return x[[IX, IY, IPSI]]


def _h_odo(_x: FloatArray) -> FloatArray:
    return _H_ODO


def _hx_odo(x: FloatArray) -> FloatArray:
    return x[[IV, IW]]


class Localizer:
    """EKF pose estimate from `GnssFix` and `Odometry` samples; see the module docstring."""

    def __init__(self, params: LocalizerParams | None = None) -> None:
        self.params = params if params is not None else LocalizerParams()
        p = self.params
        self._r_odo = np.diag([p.wheel_speed_sigma**2, p.gyro_sigma**2])  # (2, 2) constant
        self._ekf = ExtendedKalmanFilter(dim_x=DIM_X, dim_z=3)
        self._t = 0.0  # [s] time the filter state refers to
        self._initialised = False
        self._last_odo: Odometry | None = None

    def reset(self) -> None:
        """Forget everything; the next GNSS fix initialises again."""
        self._ekf = ExtendedKalmanFilter(dim_x=DIM_X, dim_z=3)
        self._t = 0.0
        self._initialised = False
        self._last_odo = None

    @property
    def initialised(self) -> bool:
        return self._initialised

    @property
    def state(self) -> FloatArray:
        """(5,) copy of ``[x, y, heading, speed, yaw_rate]`` at the last sample's time."""
        return np.array(self._ekf.x, dtype=np.float64)

    @property
    def covariance(self) -> FloatArray:
        """(5, 5) copy of the state covariance, same order and units as `state`."""
        return np.array(self._ekf.P, dtype=np.float64)

    def on_odometry(self, odo: Odometry) -> None:
        """Predict to ``odo.t`` and update with its speed and yaw rate."""
        self._last_odo = odo
        if not self._initialised:
            return
        self._predict_to(odo.t)
        self._ekf.update(np.array([odo.speed, odo.yaw_rate]), _h_odo, _hx_odo, R=self._r_odo)

    def on_gnss(self, fix: GnssFix) -> None:
        """Initialise from the first fix; later, predict to ``fix.t`` and update with it.

        A fix older than the filter time is applied at the filter time (no retrodiction): a
        fix d [s] late is off by speed x d, so the sensor model must stamp fixes on time.
        """
        if not self._initialised:
            self._initialise(fix)
            return
        self._predict_to(fix.t)
        p = self.params
        sigma = max(p.gnss_sigma, fix.sigma)
        heading_sigma = max(p.gnss_heading_sigma, fix.heading_sigma)
        r = np.diag([sigma**2, sigma**2, heading_sigma**2])
        z = np.array([fix.x, fix.y, fix.heading])
        self._ekf.update(z, _h_gnss, _hx_gnss, R=r, residual=_gnss_residual)
        self._ekf.x[IPSI] = wrap_angle(float(self._ekf.x[IPSI]))

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
        x, f = motion(x0, dt)
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

    def _initialise(self, fix: GnssFix) -> None:
        p = self.params
        odo = self._last_odo
        speed, yaw_rate = (odo.speed, odo.yaw_rate) if odo is not None else (0.0, 0.0)
        speed_sigma = p.wheel_speed_sigma if odo is not None else p.init_speed_sigma
        yaw_sigma = p.gyro_sigma if odo is not None else p.init_yaw_rate_sigma
        sigma = max(p.gnss_sigma, fix.sigma)
        heading_sigma = max(p.gnss_heading_sigma, fix.heading_sigma)
        self._ekf.x = np.array([fix.x, fix.y, wrap_angle(fix.heading), speed, yaw_rate])
        self._ekf.P = np.diag([sigma**2, sigma**2, heading_sigma**2, speed_sigma**2, yaw_sigma**2])
        self._t = fix.t
        self._initialised = True

    def _predict_to(self, t: float) -> None:
        dt = t - self._t
        if dt <= 0.0:
            return
        x0 = self.state
        x, f = motion(x0, dt)
        self._ekf.x = x
        self._ekf.P = f @ self._ekf.P @ f.T + process_noise(x0, dt, self.params)
        self._t = t
