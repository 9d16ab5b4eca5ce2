"""Which lanes are taken, from the tracks and the HD map: the motion FSM's view of the side.

Each confirmed track (map frame) is placed on the map (its box centre projected onto the
route's reference line: station [m], offset [m], left +) and counted in every lane its box
overlaps by at least ``overlap`` across. Per lane, the nearest vehicle ahead of the ego and
the nearest behind it give bumper gaps [m] along the route now (the track's station is its
scan's, carried to now at the vehicle's own speed; the car's station is now's), speeds
[m/s] along the route, and where the box lies across (its centre's offset and half its
width across the road); a box that overlaps the ego's along the route is alongside. The
tracks see all round the car (the LiDAR's 360 deg, `perception.objects`' region of interest
reaches 60 m behind as ahead), so a vehicle coming up from behind in a lane is its `behind`.

A lane is *free* for the ego to move into when nothing is alongside and

- ahead: gap >= d_min(v) + max(v - V_ahead, 0) * ``front_time`` (UN R157's minimum gap, plus
  the closing during the change). A change under way goes on behind a vehicle ahead that
  is not slower than the ego: the gap only grows, and the ego, speeding up toward its set
  speed, would otherwise give up a change for a d_min(v) that rises with its own speed
  (going back over the line it has crossed is no safer);
- behind: the vehicle approaching from behind need not brake harder than a_rear =
  ``rear_decel`` (3 m/s^2) after a reaction time t_B = ``rear_reaction`` (0.4 s) to stay a
  time gap t_G = ``rear_time_gap`` (1 s) behind the ego: `rear_decel_needed`,

      a = dv^2 / (2 (gap - dv t_B - v t_G)),   dv = max(V_behind - v, 0),

  <= a_rear, i.e. gap >= dv t_B + dv^2 / (2 a_rear) + v t_G. This is the lane-change rule
  of UN R157 (ALKS, 01 series: a lane change starts only if an approaching vehicle in the
  target lane need not decelerate harder than 3 m/s^2, 0.4 s after the change starts, to
  keep the distance the ALKS vehicle travels in 1 s) and the critical distance S_rear of UN
  R79 5.6.4.8.3 (ACSF of category C), with the regulations' values as defaults. Here it
  guards every lateral move (`planner.motion_layer`). v is the *lowest* speed the ego plans
  during the move (`v_rear`; its speed now unless it is slowing, as after a flat tyre): a car
  that brakes while it moves over lets the one behind close faster. A change under way goes
  on (the lane stays free for it) up to ``rear_decel_abort`` (hysteresis);
- behind, not braking: a faster vehicle behind that does not brake at all must not close
  to within t_G of the ego before the move is over (`rear_closes`):

      gap - dv T >= v t_G,   dv = max(V_behind - v, 0),

  T the time the move takes (`t_move`: a move under way, the time left to its end, and it
  goes on while the vehicle stays ``rear_time_gap_abort`` back: hysteresis). The rule above
  lets a car that brakes make the room; this one keeps the ego from moving out, slow, in
  front of one that does not: 37 m behind at +12.5 m/s (65 km/h on the ego at 20 km/h)
  satisfies the rule above (36.6 m) yet closes the gap in 3 s, less than a change takes
  (~5 s).

The ego's own lane is *blocked* when the vehicle ahead in it moves slower than the speed
the ego wants by more than ``block_margin`` and is within the ACC's d_max (the gap inside
which the ACC would start to trail it; `planner.fsm.acc.gaps`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from perception.messages import Track
from planner.fsm.acc import AccParams, gaps, r157_min_gap
from world.frames import VehicleInfo, kph
from world.hdmap import RoadMap


@dataclass(frozen=True, slots=True)
class OccupancyParams:
    overlap: float = 0.3  # [m] a box overlapping a lane this much across is in it
    front_time: float = 2.0  # [s] closing time allowed for a slower vehicle ahead
    rear_reaction: float = 0.4  # [s] t_B, UN R157
    rear_decel: float = 3.0  # [m/s^2] a_rear, UN R157: a move starts only below it ...
    rear_decel_abort: float = 4.0  # [m/s^2] ... and a change under way is given up (before
    #   its commit point) only above this (hysteresis: a car still slowing as it starts, or a
    #   track's speed wobble, does not start and abort a change within a second)
    rear_time_gap: float = 1.0  # [s] t_G, UN R157
    rear_time_gap_abort: float = 0.5  # [s] a vehicle behind that does not brake gives up a
    #   change under way only when it would close to within this (`rear_closes`; hysteresis
    #   over t_G: its track's speed wobbles by tenths of a m/s)
    block_margin: float = kph(10.0)  # [m/s] slower than wanted by this blocks the lane


@dataclass(frozen=True, slots=True)
class Neighbour:
    """A vehicle in a lane, relative to the ego."""

    track_id: int  # the track's id
    t: float  # [s] the track's time
    gap: float  # [m] bumper to bumper along the route, now
    speed: float  # [m/s] along the route
    offset: float = 0.0  # [m] its centre's offset from the route's reference line, left +
    half_width: float = 0.0  # [m] half its box's extent across the road
    length: float = 0.0  # [m] its box's extent along the road


@dataclass(frozen=True, slots=True)
class LaneTraffic:
    lane: int  # [-] ego-direction lane index
    ahead: Neighbour | None = None  # nearest vehicle ahead
    behind: Neighbour | None = None  # nearest vehicle behind
    alongside: bool = False  # a vehicle overlapping the ego along the route
    following: tuple[Neighbour, ...] = ()  # every vehicle behind, `behind` among them (in
    #   the tracks' order)


def lane_traffic(road: RoadMap, tracks: Sequence[Track], t: float, station: float,
                 lanes: Sequence[int], p: OccupancyParams,
                 vehicle: VehicleInfo) -> dict[int, LaneTraffic]:
    """The traffic in each of `lanes` (ego-direction lane indices) around the ego (of
    `vehicle`'s size) whose centre is at `station` [m] now, at time `t` [s]. A track's
    place is the one of its own time (the scan's, ``Track.t``): it is carried to `t` at the
    vehicle's own speed along the route; the car's `station` is already now's, so its own
    motion since the scan is not counted again."""
    out = {k: LaneTraffic(k) for k in lanes}
    if not tracks:
        return out
    xy = np.array([[tr.x, tr.y] for tr in tracks], dtype=np.float64)
    s_all, d_all = road.local_coordinates(xy)
    heading = np.asarray(road.heading_at(s_all))
    for i, tr in enumerate(tracks):
        s, d = float(s_all[i]), float(d_all[i])
        speed = tr.vx * math.cos(heading[i]) + tr.vy * math.sin(heading[i])
        half_len, half_wid = _half_extent(tr, float(heading[i]))
        dt = max(t - tr.t, 0.0)
        ahead = s + speed * dt - station  # [m] centre to centre along the route, now
        for k in lanes:
            lane = road.lane(k)
            centre, width = float(lane.offset_at(s)), float(lane.width_at(s))
            if abs(d - centre) > 0.5 * width + half_wid - p.overlap:
                continue
            n = Neighbour(tr.id, tr.t, 0.0, speed, d, half_wid, 2.0 * half_len)
            out[k] = _add(out[k], n, ahead, half_len, vehicle)
    return out


def _half_extent(tr: Track, road_heading: float) -> tuple[float, float]:
    """Half the box's extent along and across the road [m]."""
    a = tr.yaw - road_heading
    c, s = abs(math.cos(a)), abs(math.sin(a))
    return (0.5 * (tr.length * c + tr.width * s), 0.5 * (tr.length * s + tr.width * c))


def _add(lt: LaneTraffic, n: Neighbour, ahead: float, half_len: float,
         vehicle: VehicleInfo) -> LaneTraffic:
    if ahead - half_len >= vehicle.front_overhang:
        gap = ahead - half_len - vehicle.front_overhang
        if lt.ahead is None or gap < lt.ahead.gap:
            return replace(lt, ahead=replace(n, gap=gap))
        return lt
    if -ahead - half_len >= vehicle.rear_overhang:
        n = replace(n, gap=-ahead - half_len - vehicle.rear_overhang)
        nearest = n if lt.behind is None or n.gap < lt.behind.gap else lt.behind
        return replace(lt, behind=nearest, following=(*lt.following, n))
    return replace(lt, alongside=True)


def rear_decel_needed(gap: float, v_behind: float, v: float, p: OccupancyParams) -> float:
    """[m/s^2] how hard a vehicle `gap` [m] behind at `v_behind` [m/s] must brake, after
    ``rear_reaction``, to stay ``rear_time_gap`` behind the ego at `v` [m/s] (module doc);
    +inf when even braking at once cannot."""
    dv = max(v_behind - v, 0.0)
    room = gap - dv * p.rear_reaction - v * p.rear_time_gap
    if room <= 0.0:
        return 0.0 if dv == 0.0 and room == 0.0 else math.inf
    return dv * dv / (2.0 * room)


def rear_closes(gap: float, v_behind: float, v: float, t_move: float, p: OccupancyParams,
                under_way: bool = False) -> bool:
    """Whether a vehicle `gap` [m] behind at `v_behind` [m/s], not braking, comes within
    ``rear_time_gap`` (``rear_time_gap_abort`` for a move `under_way`) of the ego at `v`
    [m/s] during a move of `t_move` [s] (module doc)."""
    t_gap = p.rear_time_gap_abort if under_way else p.rear_time_gap
    return gap - max(v_behind - v, 0.0) * t_move < v * t_gap


def is_free(lt: LaneTraffic, v: float, p: OccupancyParams, v_rear: float | None = None,
            under_way: bool = False, t_move: float = 0.0) -> bool:
    """The ego at speed `v` [m/s] may move into this lane now (see the module doc); the rear
    rules are judged at `v_rear` [m/s], the lowest speed it plans during the move (`v`),
    for a move `under_way` against ``rear_decel_abort`` and ``rear_time_gap_abort``, the
    non-braking one over `t_move` [s], the time the move takes (the time left, under way;
    0: not judged)."""
    if lt.alongside:
        return False
    if lt.ahead is not None and not (under_way and lt.ahead.speed >= v):
        need = r157_min_gap(v) + max(v - lt.ahead.speed, 0.0) * p.front_time
        if lt.ahead.gap < need:
            return False
    if lt.behind is not None:
        v_low = v if v_rear is None else min(v, v_rear)
        limit = p.rear_decel_abort if under_way else p.rear_decel
        if rear_decel_needed(lt.behind.gap, lt.behind.speed, v_low, p) > limit:
            return False
        if t_move > 0.0 and rear_closes(lt.behind.gap, lt.behind.speed, v_low, t_move, p,
                                        under_way):
            return False
    return True


def is_blocked(lt: LaneTraffic, v: float, v_want: float, p: OccupancyParams,
               acc: AccParams) -> bool:
    """A vehicle ahead in this lane slower than `v_want` - margin, within the ACC's d_max."""
    lead = lt.ahead
    if lead is None or lead.speed >= v_want - p.block_margin:
        return False
    return lead.gap < gaps(v, lead.speed, acc).d_max
