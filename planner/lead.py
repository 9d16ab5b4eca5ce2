"""The vehicle ahead in the ego's lane, from LiDAR tracks, and a safe speed behind it.

Until the ACC / event layer (issue C) plans the gap, lane keeping caps its target speed so
that braking at ``a_brake`` brings the ego to the lead's speed with the gap ``d0 + tau v_l``
still free: ``v <= sqrt(v_l^2 + 2 a_brake max(gap - d0 - tau v_l, 0))``, with the lead's
speed ``v_l`` over ground along the ego's heading (>= 0). The lead is the nearest confirmed
track ahead whose centre lies within ``half_width`` of the ego lane's centre line (the
camera's lane when it is seen, else straight ahead).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from perception.messages import ObjectClass, Track
from planner.messages import Lead


@dataclass(frozen=True, slots=True)
class LeadParams:
    d0: float = 4.0  # [m] gap kept at standstill
    tau: float = 1.5  # [s] time gap
    a_brake: float = 3.0  # [m/s^2] deceleration planned towards the lead's speed
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
        room = max(gap - p.d0 - p.tau * speed, 0.0)
        best = Lead(tr.id, gap, speed, math.sqrt(speed * speed + 2.0 * p.a_brake * room))
    return best
