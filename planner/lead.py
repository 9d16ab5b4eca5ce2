"""The vehicle ahead in the ego's lane, from the LiDAR tracks (the ACC layer's d and V_l).

Two steps. Geometry first: every vehicle track ahead (not of class OTHER) is a `Candidate`,
with its gap, speed and lateral offset from the lane's centre line.

- `lane_candidates`: in the vehicle frame of the track's time (x forward, y left), the
  offset from the ego lane's centre line (the camera's lane when it is the path, else
  straight ahead; beyond the camera's reach, `far_centre`: the camera's lane continued along
  the car's heading to it and bent as the map's lane bends: the camera's curvature, fitted
  on 30 m of paint, can be 7e-4 1/m on a straight road: 1.4 m at 65 m); the gap [m]
  is bumper to bumper along the ego's heading, the speed [m/s] the track's over ground along
  the ego's heading, both at the track's time: signed as `Lead.velocity` (an oncoming car's
  < 0: the emergency braking's time to collision is the gap over the ego's speed plus the
  car's, half of the gap over the ego's speed alone at equal speeds), and at least 0 as
  `Lead.speed`, the ACC's V_l (an ACC follows no oncoming vehicle, ISO 15622); a
  pedestrian's offset is the one nearest the centre line on its way until the car reaches
  it (at the closing speed, at most ``CROSSING_HORIZON`` ahead, its velocity across the
  lane where it is; `crossing_lateral`):
  a walker crossing the road is in the car's path before it steps into the lane (a track
  classed a pedestrian but faster than ``WALKER_SPEED`` is taken as a vehicle); a vehicle
  of the ego's direction (not ``ONCOMING``) moving across the lane towards its
  centre line faster than ``CUT_IN_SPEED`` (its velocity over ground across the lane's
  direction where it is: no yaw of the ego's in it) is taken where it will be
  ``CUT_IN_HORIZON`` later (`cut_in_lateral`; its lateral speed is the track's, which lags
  the move by a few tenths of a second): a car cutting in at 1 m/s has its body
  0.2 m inside the lane 0.8 s before its centre is within 1.6 m of the centre line, and
  UN R157 5.2.5.2 counts from that intrusion (taken by its centre alone, a cut-in 30 m ahead
  at 20 km/h slower becomes the lead 0.8 s after its intrusion, too late);
- `route_candidates`, through a town junction, where the lane is the map's turn path: the
  tracks (map frame) up to ``path_reach`` ahead along the map lane kept; the gap is along the
  lane, the speed (and the signed velocity) along the lane's heading where the track is.

Then `LeadSelector` picks the lead, as a production ACC's target selection does, so that a
car in the next lane that strays near the line for a moment, or a lane's centre drawn a
little off far ahead, does not make the car brake and release:

- a vehicle is in the lane when its near side is within ``path`` of the lane's centre
  line (`Candidate.side`): the car's own half width and a margin, so that a vehicle is the
  lead before its body reaches the car's path, whatever its width (by its centre within
  1.6 m, a saloon 1.83 m wide was taken only with its body 0.12 m into the car's path: a
  cut-in at 0.5 m/s, 23 km/h slower, touched the car 0.6 s after it was taken, and a rigid
  truck 2.55 m wide, its centre 1.7 m off the centre line, overlapped the car's path by
  0.4 m without ever being the lead); a vehicle enters the lane and must stay there
  for ``confirm`` before it can become the lead (a new track or one that swerved in),
  unless it is urgent: closing with a time to collision under ``urgent_ttc`` (a cut-in
  close ahead is taken at once), or closing so fast for its gap that waiting out the
  confirmation would cost the comfortable stop that is left now (`costly_wait`: the least
  deceleration that stops the closing, `planner.acc_control.need`, is within a_comf_max at
  the gap now and beyond it at the gap the wait leaves; a stopped car first found 60 m
  ahead at 60 km/h: the wait is 5 m of a room the stop needs all of), or the stop within
  ISO's limits left now (a_iso likewise: a stopped car revealed by a cut-out 59 m ahead at
  60 km/h needs 3.16 m/s^2 now and 3.56 after the wait), or the wait would leave the gap
  within d_far of UN R157's d_min, where the ACC's d_min guard answers it
  (`planner.acc_control.guard_decel`; a car 30 km/h slower first tracked 26 m ahead at
  52 km/h, 3.6 m above d_min: waiting out the confirmation while the car sped on to its
  set speed left 0.2 m, and the gap fell 2.4 m under d_min before the braking built up);
- a cut-in is taken on the track's velocity across the lane only where the vehicle's
  offset from the lane's centre line over the last ``rate_window`` moves the same way (the
  slower of the two is taken; a new track's velocity alone): a constant-velocity track's
  velocity lags a bend, and a truck keeping the next lane beside the car crossed it by its
  velocity at 0.7 m/s (`LeadSelector._confirmed_cut_in`);
- the lead stays the lead while its near side is within ``keep`` (hysteresis: a lead swerving
  within its lane, or seen through a curve, is not dropped and taken again), unless another
  vehicle that qualifies is within ``path``: a lead leaving the lane reveals a car
  standing in it, which is the lead as soon as it qualifies (a cut-out at 1.5 m/s: 0.2 s
  earlier, 3 m of a stop from 60 km/h);
- the lead is the nearest of the vehicles that qualify.

`select_lead` and `route_lead` are the one-shot forms (no memory: every in-lane vehicle
qualifies at once), for callers that judge one moment.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from perception.messages import ObjectClass, Track
from planner.acc_control import AccControlParams, need
from planner.fsm.acc import r157_min_gap
from planner.messages import Lead
from world.hdmap import Lane

CROSSING_HORIZON = 3.0  # [s] a pedestrian's walk is predicted this far ahead at most (the
#   time to collision at which AEB pedestrian systems brake; 50 m at 60 km/h)
WALKER_SPEED = 5.0  # [m/s] a track classed a pedestrian but faster over ground than this is
#   taken as a vehicle: its first returns were boxed small (a runner makes about 4 m/s;
#   Euro NCAP's AEB pedestrian targets walk at 5 and run at 8 km/h). Its walk would be
#   predicted up to CROSSING_HORIZON ahead on a velocity its track has not settled yet: an
#   oncoming car 48 m ahead, boxed as a walker (`tracking` at 12.8 s), crossed by it.
ONCOMING = 2.0  # [m/s] a vehicle moving against the ego's heading faster than this is
#   oncoming: taken where it is, never where its velocity across the lane would take it (a
#   cut-in is a vehicle of the ego's direction moving over; an ACC follows no oncoming
#   vehicle, ISO 15622). A new track's velocity has not settled: an oncoming car's, two
#   lanes left 48 m ahead, crossed the lane at 3.6 m/s (`tracking` at 12.8 s)
WALKER_BERTH = 0.2  # [m] a walker is given this much more room beside the car than a
#   vehicle (its step aside is not signalled): in the lane with its near side within
#   `LeadParams.path` + this of the centre line (0.6 m wide: its centre within 1.6 m)
BODY_HALF_WIDTH = (0.25, 1.3)  # [m] a track's half width across the lane is taken within
#   these (a track's box grows and shrinks with its returns; the widest road vehicle is
#   2.55 m, Directive 96/53/EC)
CUT_IN_HORIZON = 1.5  # [s] a vehicle moving into the lane is taken where it will be this
#   much later (a lane change's lateral move lasts 3 to 6 s)
CUT_IN_SPEED = 0.4  # [m/s] ... if it moves across faster than this (a car keeping its lane
#   sways at 0.1 to 0.2 m/s; a lane change moves at 0.5 to 2.5 m/s)


@dataclass(frozen=True, slots=True)
class LeadParams:
    path: float = 1.1  # [m] a vehicle is in the lane when its near side is within this of
    #   the lane's centre line: the car's half width (0.8 m) and 0.3 m (a saloon 1.83 m wide:
    #   its centre within 2.0 m; a lane 3.5 m wide: the next lane's centre is 3.5 m off)
    keep: float = 1.4  # [m] the lead stays the lead while its near side is within this
    #   (hysteresis: 0.3 m wider)
    confirm: float = 0.3  # [s] a vehicle is in the lane this long before it can be the lead
    urgent_ttc: float = 2.5  # [s] ... unless it closes in faster than this
    path_reach: float = 60.0  # [m] along a map path, tracks farther ahead are not looked at
    rate_window: float = 0.5  # [s] a vehicle's offsets from the lane's centre line this far
    #   back measure its move across the lane (`LeadSelector`: a cut-in is confirmed by it)


@dataclass(frozen=True, slots=True)
class Candidate:
    """A vehicle ahead: the lead it would be, and where it is across the lane."""

    lead: Lead
    lateral: float  # [m] its centre's offset from the lane's centre line, left + (a vehicle
    #   moving into the lane: where it will be, `cut_in_lateral`)
    now: float = math.nan  # [m] a vehicle's offset where it is (NaN: as `lateral`)
    across: float = 0.0  # [m/s] its velocity across the lane towards the left, from its track
    half_width: float = 0.0  # [m] half its box's extent across the lane (`side`)
    clear: float = math.inf  # [m] how far the car must advance on it for the car's rear to
    #   pass its front: the gap and both lengths (`LeadSelector._passed_first`)

    @property
    def side(self) -> float:
        """[m] how far its near side is from the lane's centre line, at `lateral` (< 0: the
        body straddles the centre line)."""
        return abs(self.lateral) - self.half_width

    @property
    def side_now(self) -> float:
        """[m] as `side`, where it is (`now`)."""
        return abs(self.lateral if math.isnan(self.now) else self.now) - self.half_width


def far_centre(centre_y: Callable[[float], float], heading_error: float, reach: float,
               bend: Callable[[float], float]) -> Callable[[float], float]:
    """x [m] ahead -> the lane centre's lateral position [m] (vehicle frame, left +): the
    camera's `centre_y` up to `reach` [m]; beyond, its value there continued along the car's
    `heading_error` [rad] to the lane, plus how the map's lane bends from there (`bend(x)`
    [m]: the map lane centre's offset from its tangent at the car, x ahead)."""
    near, tan = centre_y(reach), math.tan(heading_error)

    def centre(x: float) -> float:
        if x <= reach:
            return centre_y(x)
        return near - tan * (x - reach) + bend(x) - bend(reach)

    return centre


BEND_STEP = 1.0  # [m] of lane between the samples of `map_bend`
BEND_REACH = 120.0  # [m] of lane sampled ahead (beyond the LiDAR's 100 m)


def map_bend(lane: Lane, s0: float, ahead: float) -> Callable[[float], float]:
    """x [m] ahead -> [m] the offset (left +) of `lane`'s centre from its tangent at station
    `s0`, at the distance x along that tangent (`ahead`: +1 along the stations, -1 against),
    for `far_centre`. The lane is sampled every ``BEND_STEP`` of its length and each sample
    placed in the tangent's frame: a distance along the lane is not a distance ahead (the
    last 26 degrees of an R 50 m bend and a straight reach 57 m ahead with 62 m of lane;
    read 62 m along, the lane's offset was 2.4 m off at 62 m ahead, and normal_driving's
    ACC trailed a car in the next lane there). Where the lane has turned so far that it no
    longer runs ahead, or beyond the samples, the offset is NaN: no lane there to be in."""
    stations = s0 + ahead * np.arange(0.0, BEND_REACH + BEND_STEP, BEND_STEP)
    stations = stations[lane.exists_at(stations)] if np.any(lane.exists_at(stations)) \
        else stations[:1]
    points = lane.position(stations, 0.0)
    h0 = float(lane.heading_at(s0)) + (0.0 if ahead > 0 else math.pi)
    c, s = math.cos(h0), math.sin(h0)
    d = points - points[0]
    forward = c * d[:, 0] + s * d[:, 1]
    lateral = c * d[:, 1] - s * d[:, 0]
    rising = np.flatnonzero(np.diff(forward) <= 0.0)
    end = int(rising[0]) + 1 if rising.size else len(forward)
    forward, lateral = forward[:end], lateral[:end]

    def bend(x: float) -> float:
        if x < 0.0 or x > forward[-1]:
            return math.nan
        return float(np.interp(x, forward, lateral))

    return bend


def crossing_lateral(lateral: float, lateral_speed: float, gap: float,
                     closing_speed: float, horizon: float = CROSSING_HORIZON) -> float:
    """[m] the offset from the lane's centre line nearest it that a walker at ``lateral``
    [m], moving across at ``lateral_speed`` [m/s], takes before the car closing in at
    ``closing_speed`` [m/s] covers the ``gap`` [m] (at most ``horizon`` [s]): 0 if it
    crosses the centre line by then."""
    if closing_speed <= 0.0:
        return lateral
    later = lateral + lateral_speed * min(horizon, max(gap, 0.0) / closing_speed)
    if lateral * later <= 0.0:
        return 0.0
    return min(lateral, later, key=abs)


def cut_in_lateral(lateral: float, lateral_speed: float, horizon: float = CUT_IN_HORIZON,
                   min_speed: float = CUT_IN_SPEED) -> float:
    """[m] the offset from the lane's centre line a vehicle at ``lateral`` [m] moving across
    at ``lateral_speed`` [m/s] (left +) is taken at: where it will be ``horizon`` [s] later
    if it moves towards the centre line faster than ``min_speed`` (0 if it would cross it by
    then), else where it is."""
    if abs(lateral_speed) <= min_speed or lateral * lateral_speed >= 0.0:
        return lateral
    later = lateral + lateral_speed * horizon
    return 0.0 if lateral * later <= 0.0 else later


def _half_width(tr: Track) -> float:
    """[m] half a track's box width, within ``BODY_HALF_WIDTH``."""
    return min(max(0.5 * tr.width, BODY_HALF_WIDTH[0]), BODY_HALF_WIDTH[1])


def lane_candidates(tracks: Sequence[Track], centre_y: Callable[[float], float],
                    ego_heading: float, front_overhang: float) -> list[Candidate]:
    """The vehicles and pedestrians ahead; `centre_y(x)` is the lane centre's lateral
    position [m] at x [m] ahead, in the vehicle frame of the tracks' time (the ego's
    `ego_heading` [rad] in the map frame); `front_overhang` [m] the ego's centre to its
    front bumper."""
    out: list[Candidate] = []
    for tr in tracks:
        if tr.cls is ObjectClass.OTHER or tr.rel_x <= 0.0:
            continue
        gap = tr.rel_x - front_overhang - 0.5 * tr.length
        along = tr.vx * math.cos(ego_heading) + tr.vy * math.sin(ego_heading)
        lead = Lead(tr.id, tr.t, gap, max(0.0, along), along)
        lateral = tr.rel_y - centre_y(tr.rel_x)
        slope = 0.5 * (centre_y(tr.rel_x + 1.0) - centre_y(tr.rel_x - 1.0))
        lane = ego_heading + math.atan(slope)  # the lane's heading where the track is
        across = tr.vy * math.cos(lane) - tr.vx * math.sin(lane)  # over ground, left +
        if tr.cls is ObjectClass.PEDESTRIAN and tr.speed <= WALKER_SPEED:  # across the
            #   lane where it is, not the car's axis: 50 m into a 250 m bend, a car keeping
            #   the oncoming lane moves across the car's axis at a fifth of its speed
            out.append(Candidate(lead, crossing_lateral(lateral, across, gap, -tr.rel_vx),
                                 half_width=_half_width(tr) + WALKER_BERTH))
        elif along < -ONCOMING:  # not a cut-in: where it is (`ONCOMING`)
            out.append(Candidate(lead, lateral, half_width=_half_width(tr)))
        else:
            out.append(Candidate(lead, cut_in_lateral(lateral, across), lateral, across,
                                 _half_width(tr), gap + 2.0 * front_overhang + tr.length))
    return out


def route_candidates(tracks: Sequence[Track], lane: Lane, station: float, p: LeadParams,
                     front_overhang: float) -> list[Candidate]:
    """The vehicles ahead on the map lane `lane` from the car's centre at `station` (the
    turn path through a town junction; map frame), up to ``path_reach``."""
    vehicles = [tr for tr in tracks if tr.cls is not ObjectClass.OTHER]
    if not vehicles:
        return []
    # near the stretch ahead of the car: a town route that crosses itself passes a junction
    # twice, and a track in it must be placed on the pass the car is on
    s, r = lane.local_coordinates(np.array([[tr.x, tr.y] for tr in vehicles]),
                                  near=station + 0.5 * p.path_reach)
    out: list[Candidate] = []
    for tr, s_tr, r_tr in zip(vehicles, np.atleast_1d(s), np.atleast_1d(r), strict=True):
        ahead = float(s_tr) - station
        if not 0.0 < ahead <= p.path_reach:
            continue
        heading = float(lane.heading_at(float(s_tr)))
        along = tr.vx * math.cos(heading) + tr.vy * math.sin(heading)
        gap = ahead - front_overhang - 0.5 * tr.length
        out.append(Candidate(Lead(tr.id, tr.t, gap, max(0.0, along), along), float(r_tr),
                             half_width=_half_width(tr)))
    return out


def _nearest(candidates: Sequence[Candidate]) -> Lead | None:
    best = min(candidates, key=lambda c: c.lead.gap, default=None)
    return None if best is None else best.lead


def select_lead(tracks: Sequence[Track], centre_y: Callable[[float], float],
                ego_heading: float, p: LeadParams, front_overhang: float) -> Lead | None:
    """The nearest vehicle ahead with its near side within ``path`` of the lane's centre line, now
    (`lane_candidates`; no confirmation)."""
    return _nearest([c for c in lane_candidates(tracks, centre_y, ego_heading, front_overhang)
                     if c.side <= p.path])


def route_lead(tracks: Sequence[Track], lane: Lane, station: float, p: LeadParams,
               front_overhang: float) -> Lead | None:
    """The nearest vehicle ahead with its near side within ``path`` of the map lane `lane`, now
    (`route_candidates`; no confirmation)."""
    return _nearest([c for c in route_candidates(tracks, lane, station, p, front_overhang)
                     if c.side <= p.path])


def costly_wait(v: float, lead: Lead, age: float, wait: float,
                acc: AccControlParams) -> bool:
    """Whether waiting `wait` [s] before taking `lead` (its track `age` [s] old) as the
    lead, the ego at `v` [m/s], would cost the comfortable stop left now, or the stop within
    ISO's limits (`AccControlParams.a_iso`) left now, or would leave the gap within d_far
    of UN R157's d_min at `v` (module doc; `need` from no braking yet)."""
    closing = v - lead.speed
    if closing <= 0.0:
        return False
    now = lead.gap - closing * age  # [m] the gap carried to now
    after_gap = now - closing * wait  # [m] the gap the wait leaves
    if after_gap - r157_min_gap(v) < acc.d_far:  # the d_min guard's band
        return True
    before = need(v, lead.speed, now, acc)
    after = need(v, lead.speed, after_gap, acc)
    return any(before <= limit < after for limit in (acc.a_comf_max, acc.a_iso))


class LeadSelector:
    """The lead over time: confirmation and hysteresis (module doc)."""

    def __init__(self, p: LeadParams, acc: AccControlParams | None = None) -> None:
        self.p = p
        self.acc = acc if acc is not None else AccControlParams()  # `costly_wait`'s laws
        self.lead_id: int | None = None  # the lead's track id
        self._since: dict[int, float] = {}  # [s] track id -> when it entered the lane
        self._offsets: dict[int, dict[float, float]] = {}  # track id -> {track time [s]:
        #   its offset from the lane's centre line [m]} over the last `rate_window`
        self._outside: set[int] = set()  # track ids seen outside the lane (`Lead.entered`)

    def select(self, t: float, ego_speed: float, candidates: Sequence[Candidate],
               ) -> Lead | None:
        """The lead at time `t` [s] from this tick's `candidates`, the ego at `ego_speed`
        [m/s]."""
        p = self.p
        candidates = [self._confirmed_cut_in(c, ego_speed) for c in candidates]
        self._offsets = {c.lead.track_id: self._offsets.get(c.lead.track_id, {})
                         for c in candidates if not math.isnan(c.now)}
        inside = {c.lead.track_id for c in candidates if c.side <= p.path}
        present = {c.lead.track_id for c in candidates}
        self._outside = {i for i in self._outside if i in present} | {
            c.lead.track_id for c in candidates if c.side_now > p.path}
        self._since = {i: self._since.get(i, t) for i in inside}
        qualified = [c for c in candidates if self._qualifies(c, t, ego_speed)]
        if any(c.side <= p.path for c in qualified):  # a lead held by the keep band alone
            qualified = [c for c in qualified if c.side <= p.path]  # yields to a vehicle in
            #   the lane: the lead leaving it reveals another
        lead = _nearest(qualified)
        self.lead_id = None if lead is None else lead.track_id
        if lead is not None and lead.track_id in self._outside:
            lead = replace(lead, entered=True)
        return lead

    def _confirmed_cut_in(self, c: Candidate, ego_speed: float) -> Candidate:
        """`c` with its offset history updated, and its cut-in (`cut_in_lateral`) kept only
        where that history agrees: the track's velocity across the lane lags its turns
        (`perception.tracking`: a constant-velocity filter), so a truck keeping the next
        lane through a 250 m bend at 60 km/h crosses it at 0.6 m/s by its velocity (ALKS
        4.1.3: taken as a cut-in alongside, emergency braking). Its offset from the lane's
        centre line over the last `rate_window`, a least-squares slope, is the second
        measure: the cut-in is taken at the slower of the two when they agree, else not;
        with too little history (a new track), at the velocity's. The lead's cut-in is kept
        down to half ``CUT_IN_SPEED``; a vehicle the car, at `ego_speed` [m/s], passes before
        it is in the lane is taken where it is (`_passed_first`)."""
        if math.isnan(c.now):
            return c
        p, i = self.p, c.lead.track_id
        history = self._offsets.setdefault(i, {})
        history[c.lead.t] = c.now
        for old in [k for k in history if k < c.lead.t - p.rate_window]:
            del history[old]
        if len(history) < 3 or max(history) - min(history) < 0.5 * p.rate_window:
            return self._passed_first(c, c.across, ego_speed)
        times = np.fromiter(history, float)
        slope = float(np.polyfit(times - times[-1], np.fromiter(history.values(), float),
                                 1)[0])
        rate = min(c.across, slope, key=abs) if c.across * slope > 0.0 else 0.0
        held = i == self.lead_id  # hysteresis: a cut-in taken as the lead stays one while it
        #   moves in at half the speed (its measured rate wavers about CUT_IN_SPEED)
        return self._passed_first(replace(c, lateral=cut_in_lateral(
            c.now, rate, min_speed=CUT_IN_SPEED * (0.5 if held else 1.0))), rate, ego_speed)

    def _passed_first(self, c: Candidate, rate: float, ego_speed: float) -> Candidate:
        """`c`, taken where it is (`now`) if it is moving into the lane at `rate` [m/s] but
        the car, at `ego_speed` [m/s], will have passed it (`clear` at the closing speed)
        before its near side is within ``path``: braking for a slower car beside the car
        that moves over keeps the car beside it, in its way (a car at 36 km/h moving in at
        0.5 m/s with the car's bumper 0.6 m past its rear: the car at 60 km/h is past it in
        1.3 s, before it is in the lane in 1.4 s; braking hard for it, the car stayed beside
        it and was struck in the side); or, beside the car (its rear behind the car's
        front), sooner than braking at ``a_hard`` would put the car behind it. The lead is
        kept as it is."""
        p = self.p
        if c.lead.track_id == self.lead_id or c.side > p.path or c.side_now <= p.path \
                or rate == 0.0:
            return c
        closing = ego_speed - c.lead.along
        if closing <= 0.0:
            return c
        passed = c.clear / closing  # [s]
        if passed < (c.side_now - p.path) / abs(rate):
            return replace(c, lateral=c.now)
        if c.lead.gap < 0.0:  # beside the car: falling back behind it at a_hard takes
            #   the closing's stop and the way back, gap = closing t - a t^2 / 2
            a = self.acc.a_hard
            behind = (closing + math.sqrt(closing**2 - 2.0 * a * c.lead.gap)) / a  # [s]
            if passed < behind:
                return replace(c, lateral=c.now)
        return c

    def take(self, lead: Lead | None) -> None:
        """`lead` is the lead by another rule (during a lane change): keep it as the lead."""
        self.lead_id = None if lead is None else lead.track_id

    def _qualifies(self, c: Candidate, t: float, ego_speed: float) -> bool:
        p, i = self.p, c.lead.track_id
        if i == self.lead_id and c.side <= p.keep:
            return True
        if i not in self._since:
            return False
        waited = t - self._since[i]
        if waited >= p.confirm - 1e-9:
            return True
        closing = ego_speed - c.lead.along  # an oncoming car's speed closes too
        return closing > 0.0 and (c.lead.gap < p.urgent_ttc * closing or costly_wait(
            ego_speed, c.lead, max(t - c.lead.t, 0.0), p.confirm - waited, self.acc))


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
