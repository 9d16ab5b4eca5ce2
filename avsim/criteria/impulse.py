"""The contact impulse: the spans of a run in which a contact, not the brakes, changes the
ego's speed, which the deceleration and jerk measures leave out.

A span runs from a contact onset (the first sample in which the ego touches a body other
than the ground and the speed bumps) until the first sample in which it touches none, plus
`SETTLE` for the body and the suspension to settle after they part. A measure over the
samples from t0 to t1 (its window: a 0.2 s deceleration, a 2 s average) is left out when
that window meets a span: its speeds then carry the collision's momentum exchange (an ego
at 60 km/h struck from the side shows 100 m/s^2 over 0.2 s), not the car's braking. A
contact still going on at the run's end spans to its end (`math.inf`).

Samples come at the criteria rate and at every contact onset (the runner samples at the
contact rate then), so the onset's sample is the first with the contact: every sample
before it precedes the contact.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from avsim.criteria.base import TruthSample

SETTLE = 0.5  # [s] after the bodies part, still the impulse's (rebound, suspension)


class ImpulseSpans:
    """The contact spans of the samples seen (module doc), sample by sample."""

    def __init__(self) -> None:
        self.closed: list[tuple[float, float]] = []  # ([s] onset, [s] parted + SETTLE)
        self.onset: float | None = None  # [s] the onset of the contact going on, if one is

    def update(self, sample: TruthSample) -> None:
        """Watch one sample's contacts."""
        if sample.touching and self.onset is None:
            self.onset = sample.t
        elif not sample.touching and self.onset is not None:
            self.closed.append((self.onset, sample.t + SETTLE))
            self.onset = None

    @property
    def spans(self) -> list[tuple[float, float]]:
        """([s] start, [s] end) of each span, the one going on to `math.inf`."""
        going_on = [] if self.onset is None else [(self.onset, math.inf)]
        return [*self.closed, *going_on]

    def meets(self, t0: float, t1: float) -> bool:
        """A measure over the samples from t0 to t1 [s] meets a span (it is left out)."""
        return meets(self.spans, t0, t1)

    def describe(self) -> str | None:
        """The spans for a note (`contact impulse left out: 3.20-4.10 s`), None if none."""
        return describe(self.spans)


def meets(spans: Sequence[tuple[float, float]], t0: float, t1: float) -> bool:
    """A window from t0 to t1 [s] meets one of `spans` ([s] start, [s] end): it holds a
    sample at or after the span's start and begins before its end."""
    return any(t1 >= start and t0 < end for start, end in spans)


def describe(spans: Sequence[tuple[float, float]]) -> str | None:
    """`contact impulse left out: 3.20-4.10 s, 9.00 s-end` ([s], `SETTLE` included), None
    when there is no span."""
    if not spans:
        return None
    shown = [f"{a:.2f}-{b:.2f} s" if math.isfinite(b) else f"{a:.2f} s-end" for a, b in spans]
    return f"contact impulse left out: {', '.join(shown)} (until {SETTLE:g} s after parting)"
