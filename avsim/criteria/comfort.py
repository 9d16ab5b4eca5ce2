"""`comfort`: the ego's automatic braking stays within ISO 15622 / ISO 22179's comfort limits
whenever the truth shows a comfortable solution existed (`criteria: {comfort: iso15622}`;
off unless set). Two criteria, on the ego's true forward speed at the criteria rate:

- `comfort_decel` [m/s^2]: the deceleration averaged over `DECEL_WINDOW` (2 s, ISO's
  measure), ``(v(t - 2 s) - v(t)) / 2 s``, is at most `A_ISO` (3.5 m/s^2);
- `comfort_jerk` [m/s^3]: the rate at which the deceleration rises, ISO's "average rate of
  change of deceleration over 1 s": the deceleration averaged over `ACCEL_WINDOW` (0.5 s,
  which filters the drivetrain's and the suspension's ripple), ``D(t) = (v(t - 0.5 s) -
  v(t)) / 0.5 s``, and the rise of its braking part over `JERK_WINDOW` (1 s), ``(D+(t) -
  D+(t - 1 s)) / 1 s`` with ``D+ = max(D, 0)``, is at most `J_ISO` (2.5 m/s^3). A
  deceleration that falls (brakes released, the car coming to rest) and an acceleration
  that tapers off (the end of a pull-away) are not judged: ISO limits the onset of
  braking.

Each window uses the newest sample at least its span back, so an extra sample (the runner
samples at each contact onset too) does not bend it.

A value whose speeds meet a contact's impulse (`avsim.criteria.impulse`: from the onset
until 0.5 s after the bodies part) is left out, of the criteria and of the run's `peaks`
alike, and the criteria's notes say so: a collision's momentum, not the brakes, changes the
speed then.

Excused (the truth shows no comfortable solution): from the first sample at which no
braking within both limits stops the ego's closing on a vehicle ahead in its lane before
a bumper gap of `D_STOP` -- against that vehicle's speed now, and, while it brakes (b_l its
deceleration), also `D_STOP` behind where it comes to rest -- such as a cut-in close ahead,
a lead braking hard, or a car standing in the lane behind a lead about to cut out (every
vehicle ahead in the lane counts, not only the nearest: the lead leaving does not move the
car it reveals), until `EXCUSE_AFTER` (2 s, the longest window) after the ego's
braking has ended (its 0.5 s deceleration under `BRAKING`). "Within both limits": the
deceleration rises from the ego's 0.5 s deceleration now at `J_ISO` to `A_ISO` and holds
(`closing_distance`), since a step to 3.5 m/s^2 is itself beyond the jerk bound: the
closing of a cut-in at 5.6 m/s ends in 4.5 m at a step to 3.5 m/s^2 but takes 8.1 m at
2.5 m/s^3 from coasting, so a cut-in 9 m ahead at that closing has no comfortable solution,
though ``(v - v_l)^2 / (2 (d - D_STOP))`` is only 2.2 m/s^2 (until 2026-11-27 the
criterion judged by that instant need against `A_ISO`, and failed such a run on its jerk).
The criterion cannot tell whether the stack itself let the vehicle come this close
unseen (braking late); `min_gap` and `no_collision` judge that.

Value: the peak judged (0 before a window first fills). Not applicable when the ego never
braked outside the excused windows (its 0.5 s deceleration never reached `BRAKING`). The
run's metrics carry the unexcused peaks of the whole run too (`peaks`: `peak_decel_2s`,
`peak_braking_jerk`), whatever the scenario's criteria.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Generic, Literal, TypeVar

import numpy as np
from numpy.typing import NDArray

from avsim.criteria.base import Criterion, CriterionResult, Need, TruthSample
from avsim.criteria.declaration import Declaration
from avsim.criteria.following import ahead_of
from avsim.criteria.impulse import ImpulseSpans, meets
from avsim.criteria.wording import beside
from world.hdmap import RoadMap

A_ISO = 3.5  # [m/s^2] ISO 15622 / 22179 (above 20 m/s): deceleration, 2 s average
J_ISO = 2.5  # [m/s^3] ISO 15622 / 22179 (above 20 m/s): rise of deceleration, 1 s average
DECEL_WINDOW = 2.0  # [s] of the deceleration's average (ISO)
ACCEL_WINDOW = 0.5  # [s] of the deceleration's average the jerk is taken from
JERK_WINDOW = 1.0  # [s] of the jerk's average (ISO)
D_STOP = 2.0  # [m] the bumper gap a comfortable solution must keep (UN R157 4.2.1)
BRAKING = 0.5  # [m/s^2] a 0.5 s deceleration at least this is braking
LEAD_BRAKING = 0.5  # [m/s^2] a vehicle ahead decelerating more brakes
EXCUSE_AFTER = DECEL_WINDOW  # [s] an excused window lasts this long after braking ends
SPAN_TOLERANCE = 1e-9  # [s] in comparing spans of sample times (sums of float steps)
ISO15622 = "iso15622"  # the setting


def closing_distance(closing: float, decel_now: float) -> float:
    """[m] the least distance in which a comfortable braking ends a closing speed `closing`
    [m/s] (a speed relative to a vehicle that keeps its own): the deceleration rises from
    the ego's now, `decel_now` [m/s^2] (clipped to [0, `A_ISO`]), at `J_ISO` to `A_ISO` and
    holds there. A step to `A_ISO` (``closing^2 / (2 A_ISO)``) would break the jerk bound
    the comfortable solution is judged by."""
    if closing <= 0.0:
        return 0.0
    a0 = min(max(decel_now, 0.0), A_ISO)
    ramp = (A_ISO - a0) / J_ISO  # [s] to reach A_ISO
    shed = a0 * ramp + 0.5 * J_ISO * ramp * ramp  # [m/s] closing shed on the way
    if closing <= shed:  # it ends during the rise
        t = (math.sqrt(a0 * a0 + 2.0 * J_ISO * closing) - a0) / J_ISO
        return closing * t - 0.5 * a0 * t * t - J_ISO * t ** 3 / 6.0
    rest = closing - shed
    return (closing * ramp - 0.5 * a0 * ramp * ramp - J_ISO * ramp ** 3 / 6.0
            + rest * rest / (2.0 * A_ISO))


def comfortable_solution(speed: float, gap: float, lead_speed: float, lead_accel: float,
                         decel_now: float) -> bool:
    """Whether a braking within ISO's limits (`closing_distance`) from the ego's speed
    [m/s] and deceleration now `decel_now` [m/s^2] stops its closing on a vehicle ahead at
    bumper gap `gap` [m] with speed `lead_speed` [m/s] before the gap falls to `D_STOP`,
    and, while that vehicle brakes (acceleration `lead_accel` [m/s^2] under
    -`LEAD_BRAKING`), stops the ego `D_STOP` behind where it comes to rest (module doc)."""
    room = gap - D_STOP
    if speed > lead_speed and closing_distance(speed - lead_speed, decel_now) > room:
        return False
    if lead_accel < -LEAD_BRAKING:
        rest = room + lead_speed * lead_speed / (2.0 * -lead_accel)
        return closing_distance(speed, decel_now) <= rest
    return True


V = TypeVar("V")


class _Window(Generic[V]):
    """The newest (t, value) at least `span` [s] before the latest one."""

    def __init__(self, span: float) -> None:
        self.span = span
        self.items: deque[tuple[float, V]] = deque()

    def push(self, t: float, value: V) -> tuple[float, V] | None:
        """Add (t, value); the sample `span` back, or None until the window has filled."""
        self.items.append((t, value))
        while len(self.items) > 1 and t - self.items[1][0] >= self.span - SPAN_TOLERANCE:
            self.items.popleft()
        t0, v0 = self.items[0]
        return (t0, v0) if t - t0 >= self.span - SPAN_TOLERANCE else None


@dataclass(frozen=True, slots=True)
class Signal:
    """A comfort value and the time of the first speed it was taken from."""

    value: float  # [m/s^2] or [m/s^3]
    since: float  # [s] its window's first speed sample


class ComfortSignals:
    """The 2 s deceleration and the braking jerk of a speed trace, sample by sample."""

    def __init__(self) -> None:
        self._decel: _Window[float] = _Window(DECEL_WINDOW)
        self._short: _Window[float] = _Window(ACCEL_WINDOW)
        self._jerk: _Window[Signal] = _Window(JERK_WINDOW)

    def push(self, t: float, speed: float) -> tuple[Signal | None, Signal | None,
                                                    Signal | None]:
        """([m/s^2] 2 s deceleration, [m/s^2] 0.5 s deceleration, [m/s^3] the rise of the
        latter's braking part over 1 s), each with its first speed's time, at time t [s]
        and speed [m/s]; None until each window has filled."""
        back = self._decel.push(t, speed)
        decel = Signal((back[1] - speed) / (t - back[0]), back[0]) \
            if back is not None and t > back[0] else None
        short_back = self._short.push(t, speed)
        if short_back is None or t <= short_back[0]:
            return decel, None, None
        short = Signal((short_back[1] - speed) / (t - short_back[0]), short_back[0])
        jerk_back = self._jerk.push(t, short)
        jerk = Signal((max(short.value, 0.0) - max(jerk_back[1].value, 0.0))
                      / (t - jerk_back[0]), jerk_back[1].since) \
            if jerk_back is not None and t > jerk_back[0] else None
        return decel, short, jerk


def peaks(t: NDArray[np.float64], speed: NDArray[np.float64],
          impulses: Sequence[tuple[float, float]] = ()) -> dict[str, float]:
    """The run's metrics: the peak 2 s deceleration `peak_decel_2s` [m/s^2] and the peak
    braking jerk `peak_braking_jerk` [m/s^3] of the speed trace (module doc), nothing
    excused but the values that meet a contact's impulse (`impulses`: ([s] start, [s]
    end) spans, `avsim.criteria.impulse`); 0 before a window fills."""
    signals = ComfortSignals()
    decel_peak = jerk_peak = 0.0
    for ti, vi in zip(t.tolist(), speed.tolist(), strict=True):
        decel, _, jerk = signals.push(ti, vi)
        if decel is not None and not meets(impulses, decel.since, ti):
            decel_peak = max(decel_peak, decel.value)
        if jerk is not None and not meets(impulses, jerk.since, ti):
            jerk_peak = max(jerk_peak, jerk.value)
    return {"peak_decel_2s": decel_peak, "peak_braking_jerk": jerk_peak}


class _Comfort(Criterion):
    """A comfort limit judged outside the excused windows (module doc)."""

    unit = ""
    limit = 0.0

    def __init__(self, road: RoadMap, ego_length: float) -> None:
        super().__init__()
        self.road, self.ego_length = road, ego_length
        self.signals = ComfortSignals()
        self.peak = 0.0  # [unit] the largest judged
        self.braked = False  # the ego braked outside the excused windows
        self.excused = 0  # how many excused windows there were
        self._in_window = False  # in an excused window
        self._excused_until = math.inf  # [s] its end, once the braking in it has ended
        self.impulses = ImpulseSpans()  # the contacts' impulses, left out

    def _measure(self, decel: Signal | None, jerk: Signal | None) -> Signal | None:
        raise NotImplementedError

    def after_judging(self, sample: TruthSample) -> None:
        """The contact spans go on (the note shows where they ended)."""
        self.impulses.update(sample)

    def update(self, sample: TruthSample) -> None:
        self.impulses.update(sample)
        decel, short, jerk = self.signals.push(sample.t, sample.speed)
        braking = short is not None and short.value >= BRAKING
        ahead = ahead_of(sample, self.road, self.ego_length)
        decel_now = max(short.value if short is not None else 0.0, 0.0)
        comfortable = all(comfortable_solution(sample.speed, a.gap, a.speed, a.accel, decel_now)
                          for a in ahead)
        if not comfortable:  # a window opens (or goes on)
            self.excused += 0 if self._in_window else 1
            self._in_window, self._excused_until = True, math.inf
        elif self._in_window:  # it lasts until EXCUSE_AFTER after the braking has ended
            if braking:
                self._excused_until = math.inf
            elif self._excused_until == math.inf:
                self._excused_until = sample.t + EXCUSE_AFTER
            self._in_window = sample.t <= self._excused_until
        if self._in_window or (short is not None and self.impulses.meets(short.since, sample.t)):
            return
        self.braked = self.braked or braking
        signal = self._measure(decel, jerk)
        if signal is None or self.impulses.meets(signal.since, sample.t):
            return
        value = signal.value
        self.peak = max(self.peak, value)
        if value > self.limit:
            shown = beside(value, self.limit, 2)
            self._fail(sample, f"{self.name} {shown} {self.unit} beyond {self.limit:g} "
                               f"{self.unit} with a comfortable solution at hand")

    def result(self) -> CriterionResult:
        if not self.braked:
            why = f" ({self.excused} braking(s) excused: no comfortable solution by the " \
                  f"truth)" if self.excused else ""
            return CriterionResult.not_applicable(
                self.name, self.limit, self.unit,
                "; ".join(filter(None, [f"the ego never braked{why}",
                                        self.impulses.describe()])))
        return CriterionResult(self.name, self.first_failure is None, self.peak, self.limit,
                               self.unit, self.first_failure, note=self.impulses.describe())


class ComfortDecel(_Comfort):
    """ISO 15622's deceleration bound: the 2 s deceleration at most `A_ISO`."""

    name, unit, limit = "comfort_decel", "m/s^2", A_ISO

    def _measure(self, decel: Signal | None, jerk: Signal | None) -> Signal | None:
        return decel


class ComfortJerk(_Comfort):
    """ISO 15622's jerk bound: the deceleration rises at most at `J_ISO`."""

    name, unit, limit = "comfort_jerk", "m/s^3", J_ISO

    def _measure(self, decel: Signal | None, jerk: Signal | None) -> Signal | None:
        return jerk


COMFORT: Declaration[str] = Declaration(
    build=lambda _, run: [ComfortDecel(run.road, run.car.body_length),
                          ComfortJerk(run.road, run.car.body_length)],
    needs=frozenset({Need.MAP, Need.CAR, Need.ACTORS}), key="comfort",
    setting=Literal["iso15622"],
    doc="`iso15622`: the ego's deceleration (2 s average) stays at most 3.5 m/s^2 and its "
    "rise (the 0.5 s deceleration's change over 1 s) at most 2.5 m/s^3, except where the "
    "truth shows no comfortable solution (stopping the closing on the vehicle ahead 2 m "
    "short of it needs more than 3.5 m/s^2); criteria `comfort_decel` and `comfort_jerk`, "
    "not applicable when the ego never braked. Default: off.", example=ISO15622)
