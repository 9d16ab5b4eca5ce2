"""A discrete PID controller with integrator clamp and a low-passed derivative.

u = kp * e + ki * integral(e dt) + kd * de/dt, evaluated once per `update(error, dt)`.

- Anti-windup: the integral *term* (ki * integral) is clamped to +-`integral_limit`, in output
  units, so the limit keeps its meaning when `ki` is retuned; callers may also freeze
  integration for a step (`integrate=False`, conditional integration while their output is
  saturated).
- Derivative: the backward difference of the error, through a first-order low-pass with time
  constant `derivative_tau` (backward-Euler discretisation, alpha = dt / (tau + dt)). The first
  step after `reset()` has no previous error, so its derivative is 0 (no derivative kick).

Units are the caller's: with an error in [E] and an output in [U], kp is [U/E], ki [U/(E s)],
kd [U s/E].
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

__all__ = ["Pid", "PidGains", "PidParams"]


class PidGains(Protocol):
    """Anything carrying the five PID fields (a loop's own parameter set)."""

    @property
    def kp(self) -> float: ...
    @property
    def ki(self) -> float: ...
    @property
    def kd(self) -> float: ...
    @property
    def integral_limit(self) -> float: ...
    @property
    def derivative_tau(self) -> float: ...


@dataclass(frozen=True, slots=True)
class PidParams:
    """Gains and limits of one PID loop (error [E], output [U])."""

    kp: float  # [U/E] proportional gain
    ki: float = 0.0  # [U/(E s)] integral gain
    kd: float = 0.0  # [U s/E] derivative gain
    integral_limit: float = math.inf  # [U] |ki * integral| is clamped to this (anti-windup)
    derivative_tau: float = 0.0  # [s] time constant of the derivative low-pass (0: unfiltered)

    @classmethod
    def of(cls, g: PidGains) -> PidParams:
        """The PID part of a loop's parameter set."""
        return cls(kp=g.kp, ki=g.ki, kd=g.kd, integral_limit=g.integral_limit,
                   derivative_tau=g.derivative_tau)

    def __post_init__(self) -> None:
        if self.integral_limit < 0.0:
            raise ValueError(f"integral_limit must be >= 0, got {self.integral_limit}")
        if self.derivative_tau < 0.0:
            raise ValueError(f"derivative_tau must be >= 0, got {self.derivative_tau}")


class Pid:
    """PID state (integral term, previous error, filtered derivative) with `reset`/`update`."""

    def __init__(self, params: PidParams) -> None:
        self.params = params
        self._integral_term = 0.0  # [U] ki * integral(e dt), already clamped
        self._previous_error: float | None = None  # [E]
        self._derivative = 0.0  # [E/s] low-passed de/dt

    @property
    def integral_term(self) -> float:
        """[U] the current integral contribution ki * integral(e dt)."""
        return self._integral_term

    @property
    def derivative(self) -> float:
        """[E/s] the current low-passed error derivative."""
        return self._derivative

    def reset(self) -> None:
        """Forget the integral, the previous error and the derivative."""
        self._integral_term = 0.0
        self._previous_error = None
        self._derivative = 0.0

    def update(self, error: float, dt: float, *, integrate: bool = True) -> float:
        """Advance one step of `dt` [s] with `error` [E]; return the output [U].

        With `integrate=False` the integral term is held (not reset) for this step.
        """
        if not dt > 0.0:
            raise ValueError(f"dt must be > 0, got {dt}")
        p = self.params
        if integrate:
            limit = p.integral_limit
            self._integral_term = min(max(self._integral_term + p.ki * error * dt, -limit), limit)
        if self._previous_error is not None:
            raw = (error - self._previous_error) / dt
            alpha = dt / (p.derivative_tau + dt)
            self._derivative += alpha * (raw - self._derivative)
        self._previous_error = error
        return p.kp * error + self._integral_term + p.kd * self._derivative
