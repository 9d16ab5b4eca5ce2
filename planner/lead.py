"""The vehicle ahead in the ego's lane, from the LiDAR tracks (the ACC layer's d and V_l).

`select_lead`: the lead is the nearest confirmed track ahead (vehicle frame of the track's
time, x forward, y left; not of class OTHER) whose centre lies within ``half_width`` of the
ego lane's centre line (the camera's lane when it is the path, else straight ahead); its
gap [m] is bumper to bumper along the ego's heading, its speed [m/s] the track's over
ground along the ego's heading (>= 0), both at the track's time.

A pedestrian walking into the lane counts before it is in it: its lateral position where it
will be when the ego reaches it (its gap over the ego's speed, at most ``walk_horizon``),
from its lateral speed over ground across the ego's heading, is within ``half_width`` (a
walker stepping onto a motorway, UN R157 ALKS 4.2.3: seen only once in the lane it is too
close to stop for).

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
    walk_horizon: float = 4.0  # [s] a walker's lateral motion is looked ahead at most this
    path_reach: float = 60.0  # [m] along a map path, tracks farther ahead are not looked at


def select_lead(tracks: Sequence[Track], centre_y: Callable[[float], float],
                ego_heading: float, p: LeadParams, front_overhang: float,
                ego_speed: float = 0.0) -> Lead | None:
    """The nearest in-lane vehicle ahead, or walker heading into the lane (module doc);
    `centre_y(x)` is the lane centre's lateral position [m] at x [m] ahead, in the vehicle
    frame of the tracks' time; `front_overhang` [m] the ego's centre to its front bumper;
    `ego_speed` [m/s] its speed."""
    best: Lead | None = None
    for tr in tracks:
        if tr.cls is ObjectClass.OTHER or tr.rel_x <= 0.0:
            continue
        gap = tr.rel_x - front_overhang - 0.5 * tr.length
        if _off_lane(tr, centre_y(tr.rel_x), gap, ego_heading, ego_speed, p):
            continue
        if best is not None and gap >= best.gap:
            continue
        speed = max(0.0, tr.vx * math.cos(ego_heading) + tr.vy * math.sin(ego_heading))
        best = Lead(tr.id, tr.t, gap, speed)
    return best


def _off_lane(tr: Track, centre: float, gap: float, ego_heading: float, ego_speed: float,
              p: LeadParams) -> bool:
    """Whether track `tr` stays out of the lane (beyond ``half_width`` of its centre line at
    `centre` [m]): now, and for a walker until the ego reaches it (module doc)."""
    now = tr.rel_y - centre
    if tr.cls is not ObjectClass.PEDESTRIAN or ego_speed <= 0.0:
        return abs(now) > p.half_width
    ahead = min(max(gap, 0.0) / ego_speed, p.walk_horizon)  # [s] till the ego is there
    across = -tr.vx * math.sin(ego_heading) + tr.vy * math.cos(ego_heading)  # [m/s]
    then = now + across * ahead
    nearest = 0.0 if now * then <= 0.0 else min(abs(now), abs(then))  # it walks straight
    return nearest > p.half_width


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
