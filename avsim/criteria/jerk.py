"""`max_jerk`: the ego's longitudinal jerk stays within the scenario's threshold; off unless
the scenario sets it (`criteria: {max_jerk: 10}`, [m/s^3]).

The jerk is the derivative of the ego's true longitudinal acceleration, on a `JERK_WINDOW`
moving average. From the samples (t_k [s], v_k [m/s] true forward speed):

1. a_k = (v_k - v_(k-1)) / (t_k - t_(k-1)), the acceleration between two samples [m/s^2],
   at the time between them, m_k = (t_k + t_(k-1)) / 2;
2. j_k = (a_k - a_i) / (m_k - m_i), with a_i the newest acceleration at least
   `JERK_WINDOW` before a_k: the mean jerk over the window, which is the derivative of the
   acceleration's moving average over it [m/s^3].

At a steady criteria rate f, a_i is a_(k-N) with N = JERK_WINDOW f (a whole number) and
j_k = (a_k - a_(k-N)) f / N; the first is judged at the (N + 2)th sample. The samples' own
times are used, so an extra sample (the runner samples at each contact onset too) does not
bend it: under a constant jerk every a_k is the acceleration at m_k exactly, and every j_k
the jerk.

A j_k whose speeds (from t_(i-1) to t_k) meet a contact's impulse (`avsim.criteria.impulse`:
from the onset until 0.5 s after the bodies part) is left out, and the note says so: a
collision's momentum, not the drive or the brakes, changes the speed then.

Value: the largest |j_k| [m/s^3], speeding up or braking (0 before the window first fills).
It fails at the first sample with |j_k| over the threshold, an infraction then.
"""

from __future__ import annotations

from collections import deque

from avsim.criteria.base import Criterion, CriterionResult, TruthSample
from avsim.criteria.declaration import Declaration
from avsim.criteria.impulse import ImpulseSpans
from avsim.criteria.wording import beside, signed
from avsim.scenario.fields import PosFloat

JERK_WINDOW = 0.2  # [s] of the moving average
TIME_TOLERANCE = 1e-9  # [s] in comparing spans of sample times (sums of float steps)


class MaxJerk(Criterion):
    """The ego's longitudinal jerk (module doc) never exceeds the threshold [m/s^3] in
    magnitude."""

    name, unit = "max_jerk", "m/s^3"

    def __init__(self, threshold: float) -> None:
        super().__init__()
        self.threshold = threshold
        self.peak = 0.0  # [m/s^3]
        self._last: tuple[float, float] | None = None  # ([s], [m/s]) the previous sample
        self._accels: deque[tuple[float, float, float]] = deque()  # ([s] m_i, [m/s^2] a_i,
        #   [s] t_(i-1): its first speed's time)
        self.impulses = ImpulseSpans()

    def after_judging(self, sample: TruthSample) -> None:
        """The contact spans go on (the note shows where they ended)."""
        self.impulses.update(sample)

    def update(self, sample: TruthSample) -> None:
        self.impulses.update(sample)
        last, self._last = self._last, (sample.t, sample.speed)
        if last is None or sample.t <= last[0]:
            return
        m = 0.5 * (sample.t + last[0])
        self._accels.append((m, (sample.speed - last[1]) / (sample.t - last[0]), last[0]))
        while len(self._accels) > 1 and m - self._accels[1][0] >= JERK_WINDOW - TIME_TOLERANCE:
            self._accels.popleft()  # keep the newest acceleration a window back, no older
        m0, a0, since = self._accels[0]
        if m - m0 < JERK_WINDOW - TIME_TOLERANCE or self.impulses.meets(since, sample.t):
            return  # the window has not filled yet, or a contact moves the car
        jerk = (self._accels[-1][1] - a0) / (m - m0)
        self.peak = max(self.peak, abs(jerk))
        if abs(jerk) > self.threshold:
            self._fail(sample, f"longitudinal jerk {signed(jerk, 1)} m/s^3 (magnitude "
                               f"{beside(abs(jerk), self.threshold)}) beyond "
                               f"{self.threshold:g} m/s^3")

    def result(self) -> CriterionResult:
        return CriterionResult(self.name, self.peak <= self.threshold, self.peak,
                               self.threshold, self.unit, self.first_failure,
                               note=self.impulses.describe())


MAX_JERK: Declaration[float] = Declaration(
    build=lambda threshold, _: [MaxJerk(threshold)], needs=frozenset(), key="max_jerk",
    setting=PosFloat, example=10.0,
    doc="[m/s^3] the ego's longitudinal jerk (the derivative of its true longitudinal "
    "acceleration, 0.2 s average) never exceeds it in magnitude, > 0; a contact's impulse "
    "(from its onset until 0.5 s after the bodies part) is left out. Default: off.")
