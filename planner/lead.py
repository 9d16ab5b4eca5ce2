"""The vehicle ahead in the ego's lane, from the LiDAR tracks (the ACC layer's d and V_l).

`select_lead`: the lead is the nearest confirmed track ahead (vehicle frame of the track's
time, x forward, y left; not of class OTHER) whose centre lies within ``half_width`` of the
ego lane's centre line (the camera's lane when it is the path, else straight ahead); its
gap [m] is bumper to bumper along the ego's heading, its speed [m/s] the track's over
ground along the ego's heading (>= 0), both at the track's time.

`route_lead`, through a town junction, where the lane is the map's turn path: the lead is
the nearest track (map frame) up to ``path_reach`` ahead along the map lane kept whose
centre is within ``half_width`` of it; its gap is along the lane, its speed along the
lane's heading where it is.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from perception.messages import ObjectClass, Track
from planner.messages import Lead
from world.hdmap import Lane


@dataclass(frozen=True, slots=True)
class LeadParams:
    half_width: float = 1.6  # [m] a track is in the lane within this of its centre line
    path_reach: float = 60.0  # [m] along a map path, tracks farther ahead are not looked at


def select_lead(tracks: Sequence[Track], centre_y: Callable[[float], float],
                ego_heading: float, p: LeadParams, front_overhang: float) -> Lead | None:
    """The nearest in-lane vehicle ahead; `centre_y(x)` is the lane centre's lateral position
    [m] at x [m] ahead, in the vehicle frame of the tracks' time; `front_overhang` [m] the
    ego's centre to its front bumper."""
    best: Lead | None = None
    for tr in tracks:
        if tr.cls is ObjectClass.OTHER or tr.rel_x <= 0.0:
            continue
        if abs(tr.rel_y - centre_y(tr.rel_x)) > p.half_width:
            continue
        gap = tr.rel_x - front_overhang - 0.5 * tr.length
        if best is not None and gap >= best.gap:
            continue
        speed = max(0.0, tr.vx * math.cos(ego_heading) + tr.vy * math.sin(ego_heading))
        best = Lead(tr.id, tr.t, gap, speed)
    return best


def route_lead(tracks: Sequence[Track], lane: Lane, station: float, p: LeadParams,
               front_overhang: float) -> Lead | None:
    """The nearest vehicle ahead on the map lane `lane` from the car's centre at `station`
    (the turn path through a town junction; map frame)."""
    vehicles = [tr for tr in tracks if tr.cls is not ObjectClass.OTHER]
    if not vehicles:
        return None
    s, r = lane.local_coordinates(np.array([[tr.x, tr.y] for tr in vehicles]))
    best: Lead | None = None
    for tr, s_tr, r_tr in zip(vehicles, np.atleast_1d(s), np.atleast_1d(r), strict=True):
        ahead = float(s_tr) - station
        if not 0.0 < ahead <= p.path_reach or abs(float(r_tr)) > p.half_width:
            continue
        gap = ahead - front_overhang - 0.5 * tr.length
        if best is not None and gap >= best.gap:
            continue
        heading = float(lane.heading_at(float(s_tr)))
        speed = max(0.0, tr.vx * math.cos(heading) + tr.vy * math.sin(heading))
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
