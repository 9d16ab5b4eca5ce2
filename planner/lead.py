"""The vehicle ahead in the ego's lane, from the LiDAR tracks (the ACC layer's d and V_l).

The lead is the nearest confirmed track ahead whose centre lies within ``half_width`` of the
ego lane's centre line (the camera's lane when it is seen, else straight ahead); its gap is
bumper to bumper along the ego's heading, its speed the track's over ground along the ego's
heading (>= 0), both at the track's time.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from perception.messages import ObjectClass, Track
from planner.messages import Lead


@dataclass(frozen=True, slots=True)
class LeadParams:
    half_width: float = 1.6  # [m] a track is in the lane within this of its centre line
    front_overhang: float = 2.4  # [m] the ego's centre -> front bumper


def select_lead(tracks: Sequence[Track], centre_y: Callable[[float], float],
                ego_heading: float, p: LeadParams) -> Lead | None:
    """The nearest in-lane vehicle ahead; `centre_y(x)` is the lane centre's lateral position
    [m] at x [m] ahead, in the vehicle frame of the tracks' time."""
    best: Lead | None = None
    for tr in tracks:
        if tr.cls is ObjectClass.OTHER or tr.rel_x <= 0.0:
            continue
        if abs(tr.rel_y - centre_y(tr.rel_x)) > p.half_width:
            continue
        gap = tr.rel_x - p.front_overhang - 0.5 * tr.length
        if best is not None and gap >= best.gap:
            continue
        speed = max(0.0, tr.vx * math.cos(ego_heading) + tr.vy * math.sin(ego_heading))
        best = Lead(tr.id, tr.t, gap, speed)
    return best


class LeadAccel:
    """The lead's acceleration [m/s^2]: the derivative of its track speed between track
    updates, through a first-order low-pass of time constant `tau` [s]; 0 for a new lead."""

    def __init__(self, tau: float = 0.3) -> None:
        self.tau = tau
        self._id: int | None = None
        self._t = 0.0
        self._v = 0.0
        self.accel = 0.0

    def update(self, lead: Lead | None) -> float:
        if lead is None or lead.track_id != self._id:
            self._id = None if lead is None else lead.track_id
            self.accel = 0.0
        elif lead.t > self._t:
            dt = lead.t - self._t
            raw = (lead.speed - self._v) / dt
            self.accel += dt / (self.tau + dt) * (raw - self.accel)
        if lead is not None:
            self._t, self._v = lead.t, lead.speed
        return self.accel
