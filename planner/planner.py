"""The planner's tick: the ICCAS dual FSM with the DECS ACC / event layer, for one route road.

`Planner.update` takes the one message perception hands it each control tick
(`perception.messages.PlannerInput`: the ego estimate, the camera's lane, the confirmed
tracks, the signs and light colours of a frame, the driver's accelerator pedal, the
flat-tyre flag and the sensors' health) and returns the `Plan` (`planner.messages`).
Nothing else calls into it. Positions are in the map frame, stations [m] along the route's
reference line, speeds [m/s]. Steps:

1. the signs and light colours of a frame are matched with the map's stop lines and lights
   (`planner.events`, `planner.junctions`);
2. the car is placed on the lane kept (station, lateral offset); the lane-source FSM
   (`planner.fsm.lane_source`) says where the lateral reference comes from: the camera's
   lane (on both its lines, or on one: ONE_LINE), or the map lane
   (`planner.route.lane_path`, placed by the pose estimate) while the camera's is acquired,
   lost or another lane than the one kept, or near a town junction;
3. the motion FSM (`planner.motion_layer`) keeps the lane, changes lanes from the lane
   occupancy of the tracks, turns at a junction or pulls over; a lane change (or its
   abort) makes its target lane the lane kept and its Hermite path
   (`planner.lane_change_path`) the path. Otherwise the path is the camera's lane
   (`planner.camera_lane`) when the source is CAMERA or ONE_LINE (the camera sees the lane kept: its
   offset agrees with the map's within ``camera_agree`` at the frame's pose, which the
   camera's lane itself corrects across the lane) and the lane is not the shoulder, else
   the map lane (ACQUIRING at the start, before the camera's lane has corrected the pose
   across the lane: the line parallel to the lane through the car, holding its offset); the
   lane source is updated once the lane kept is known; with the shoulder the lane kept, the
   path is moved across the road by the pose's error that the camera's view of the
   shoulder's one painted line tells (`planner.shoulder_line`);
4. the lead vehicle (`planner.lead`: in the path's lane, or along the map lane through a
   junction, or in the lanes a lane change occupies);
5. the speed, a chain of `planner.speed.PlannedSpeed`s, each link keeping what it was given
   unless it lowers it: the map's plan (`planner.speed_planning`: set speed, the sight cap
   (`SpeedSource.SIGHT`), the lane kept's limits and curves), the driver's pedal
   (`planner.driver_override`: it raises the plan up to the limit), the ACC / event law
   (`planner.acc_layer`: cruise, trail or brake behind the lead, which is nearer by the
   motion layer's room to pull out when it is a stationary vehicle the car may pass; a
   stop, a bump's pass speed, a flat tyre's crawl), the degraded modes' cap (ramped down at
   ``a_comf`` to the hold speed in MAP_HOLD, to a stop in STOP_IN_LANE; to the slow speed
   when the sensing machine, `planner.fsm.sensing`, answers a faulty GNSS with DEGRADED, to
   a stop in lane when it answers a lost LiDAR with MINIMUM_RISK: the sensors' health as
   `perception.health` noticed it) and the emergency stop; the plan's `speed_source` is the
   link that set the speed;
6. while the automated driving function is not engaged (`PlannerInput.engaged`: an
   OpenSCENARIO file's car under test before its controller is activated; or overridden
   by the driver's brake until he switches it on again) the ACC is off (ACC_OFF) and the
   driver drives (`SpeedSource.DRIVER`) in the lane kept, whatever is ahead: his brake, or
   the speed he holds, moved to his set speed at a comfortable rate
   (`planner.driver_inputs`); the emergency stop below stays on, and once it has stopped
   the car the driver holds it until the way ahead is clear (the AEB's standstill hold).
   The set speed is the driver's last choice (`PlannerInput.driver`), else the configured
   one; his turn-signal stalk asks the motion FSM for a lane (step 3);
7. the control FSM (`planner.control_layer`) names the control action and, in an
   emergency, asks for the emergency stop's deceleration instead; the hazard lights go on
   with a flat tyre, and during a minimum-risk stop in lane after a sensor fault (off again
   when it is over: `planner.fsm.hazard`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from perception.messages import EgoState, LaneView, PlannerInput, Track
from planner.acc_layer import AccLayer, AccLayerParams
from planner.camera_lane import camera_lane_path
from planner.control_layer import ControlLayer
from planner.driver_inputs import DriverInputs, DriverParams
from planner.driver_override import DriverOverride, OverrideParams
from planner.events import EventMonitor, EventParams
from planner.fsm import hazard, lane_source, sensing
from planner.fsm.acc import sight_speed
from planner.fsm.control import ControlState
from planner.fsm.hazard import HazardInput, HazardLights
from planner.fsm.lane_source import LaneSource, LaneSourceInput, LaneSourceParams
from planner.fsm.machine import Machine, StateChange
from planner.fsm.sensing import Sensing, SensingInput, SensingParams
from planner.junctions import JunctionMonitor, JunctionParams
from planner.lead import (
    LeadAccel,
    LeadParams,
    LeadSelector,
    far_centre,
    lane_candidates,
    map_bend,
    route_candidates,
)
from planner.limits import A_EMERGENCY, SIGHT
from planner.messages import Lead, Plan, ReferencePath, SpeedSource
from planner.motion_layer import Manoeuvre, MotionLayer, MotionLayerParams
from planner.route import lane_path
from planner.shoulder_line import ShoulderLine, ShoulderLineParams, shifted
from planner.speed import BINDING_SOURCE, PlannedSpeed, SpeedRef
from planner.speed_planning import Binding, SpeedPlanner, SpeedPlanningParams, SpeedTarget
from world.frames import VehicleInfo
from world.hdmap import SHOULDER, RoadMap

__all__ = ["MotionLayerParams", "Planner", "PlannerParams"]  # the front door

_CAMERA_LANE = frozenset({LaneSource.CAMERA, LaneSource.ONE_LINE})  # the camera's lane is the
#   path (the lane kept, on both lines or on one)


@dataclass(frozen=True, slots=True)
class PlannerParams:
    set_speed: float  # [m/s] the driver's desired (cruise) speed
    max_speed: float  # [m/s] the vehicle's maximum speed
    vehicle: VehicleInfo  # the car's dimensions
    lane: int = 0  # [-] ego-direction lane index to keep (0 rightmost)
    path_behind: float = 5.0  # [m] path sampled behind the car's centre
    path_ahead_min: float = 25.0  # [m] shortest path ahead of the car's centre
    path_ahead_time: float = 2.5  # [s] path ahead = max(path_ahead_min, this * speed)
    path_spacing: float = 0.5  # [m] station step of the path samples
    camera: bool = True  # False: no camera in this stack, the map lane only (state MAP)
    camera_ahead: float = 30.0  # [m] the camera's lane is used this far ahead of its frame
    speed: SpeedPlanningParams = field(default_factory=SpeedPlanningParams)
    source: LaneSourceParams = field(default_factory=LaneSourceParams)
    sensing: SensingParams = field(default_factory=SensingParams)
    lead: LeadParams = field(default_factory=LeadParams)
    acc: AccLayerParams = field(default_factory=AccLayerParams)
    motion: MotionLayerParams = field(default_factory=MotionLayerParams)
    override: OverrideParams = field(default_factory=OverrideParams)
    driver: DriverParams = field(default_factory=DriverParams)
    events: EventParams = field(default_factory=EventParams)
    junctions: JunctionParams = field(default_factory=JunctionParams)
    shoulder_line: ShoulderLineParams = field(default_factory=ShoulderLineParams)
    camera_agree: float = 1.0  # [m] the camera's lane is used only within this of the map's
    junction_before: float = 10.0  # [m] before a town junction's stop line ...
    junction_after: float = 15.0  # [m] ... to after its exit, the map's path is followed
    sight_range: float = SIGHT  # [m] the bumper gap at which the forward LiDAR's track of a
    #   car ahead is confirmed (measured: 53 m; its lowest ring that clears the ground meets
    #   a car's rear too low beyond about 72 m, `perception.objects.DetectorParams.roi_x`,
    #   and nearer than that one ring's few returns are found in too few scans); the speed
    #   plan never exceeds the speed whose desired gap and emergency stop lie within it
    #   (`planner.fsm.acc.sight_speed`: 91 km/h)


@dataclass(frozen=True, slots=True, eq=False)
class LateralChoice:
    """The path of one tick and whether it is the camera's lane."""

    path: ReferencePath
    camera: bool  # the camera's lane is seen, agrees with the map's, and is the path


class Planner:
    """Follows lane ``params.lane`` of ``road`` from the perception message of each tick
    (module doc); `reset` starts it over."""

    def __init__(self, road: RoadMap, params: PlannerParams) -> None:
        if params.lane < 0:
            raise ValueError(f"the planner needs an ego-direction lane, got {params.lane}")
        self.road = road
        self.params = params
        self._speed_planners: dict[int, SpeedPlanner] = {}
        self.max_speed = params.max_speed  # [m/s]
        self.sight_speed = sight_speed(  # [m/s] the cap of the forward sensing range
            params.sight_range, params.acc.modes, A_EMERGENCY)
        self.reset()

    def reset(self) -> None:
        """Back to ACQUIRING the lane (MAP without a camera) of `params.lane`, keeping it,
        with no speed cap."""
        p = self.params
        self.source = Machine("lane_source",
                              LaneSource.ACQUIRING if p.camera else LaneSource.MAP)
        self._start: float | None = None  # [s] time of the first tick
        self._station: float | None = 0.0  # [m] the car's station when last localised (first:
        #   the route's start, where its mission begins; a town route may run along its start
        #   street again later, and the nearest pass there is either)
        self._standing = 0.0  # [s] the car has stood since the lane source's state was
        #   entered (`LaneSourceInput.standing`)
        self._lane_seen = False  # the camera's lane has been the path (the pose is matched)
        self._cap = math.inf  # [m/s] the ramped speed cap of the degraded modes
        self._last_t: float | None = None
        self._keep(p.lane)
        self.acc = AccLayer(p.acc)
        self.motion = MotionLayer(self.road, p.lane, p.acc.modes, p.vehicle, p.motion)
        self.control = ControlLayer()
        self.lead_accel = LeadAccel()
        self.leads = LeadSelector(self.params.lead, self.params.acc.control)
        self.driver = DriverOverride(p.override)
        self.inputs = DriverInputs(p.set_speed, p.max_speed, p.driver)
        self.events = EventMonitor(self.road, p.vehicle, p.events)
        self._waiting: frozenset[float] = frozenset()  # [m] the crosswalks ahead where a
        #   pedestrian waits this tick (`EventMonitor.waiting`: a lower crossing speed)
        self.junctions = JunctionMonitor(self.road, p.vehicle, p.junctions)
        self.hazard = Machine("hazard", HazardLights.OFF)
        self.sensing = Machine("sensing", Sensing.NOMINAL)
        self.shoulder_line = ShoulderLine(p.shoulder_line)

    def _keep(self, lane: int) -> None:
        """Make `lane` the lane whose stations, speed plan and map path are used."""
        self.lane_index = lane
        self.lane = self.road.lane(lane)
        if lane not in self._speed_planners:
            self._speed_planners[lane] = SpeedPlanner(self.road, self.lane, self.params.speed,
                                                      self.params.vehicle)
        self.speed_planner = self._speed_planners[lane]

    def localise(self, ego: EgoState) -> tuple[float, float]:
        """(station [m], lateral offset [m], left +) of the ego's centre on the lane kept:
        near the station it had (a town route through a junction it crossed before passes
        the same point twice: `world.hdmap.ReferenceLine.project`)."""
        s, r = self.lane.local_coordinates(np.array([ego.x, ego.y]), self._station)
        self._station = float(np.asarray(s))
        return self._station, float(np.asarray(r))

    def path_for(self, ego: EgoState, station: float, offset: float = 0.0) -> ReferencePath:
        """The lane kept's centre (or the line `offset` [m] left of it) from ``path_behind``
        behind the car's centre at `station` [m] to max(``path_ahead_min``,
        ``path_ahead_time`` * speed) ahead."""
        p = self.params
        ahead = max(p.path_ahead_min, p.path_ahead_time * max(ego.speed, 0.0))
        return lane_path(self.lane, station, p.path_behind, ahead, p.path_spacing,
                         length=self.road.length, offset=offset)

    def speed_for(self, station: float, set_speed: float | None = None) -> SpeedTarget:
        """The map's speed target for the car's centre at ``station`` [m] (at ``set_speed``
        [m/s], by default the driver's set speed), never above the sight cap (its binding
        SIGHT where the cap is what limits it); slower towards a crosswalk where a
        pedestrian waits (this tick's `EventMonitor.waiting`)."""
        return self.speed_planner.target(
            station, set_speed=self.inputs.set_speed if set_speed is None else set_speed,
            max_speed=self.max_speed, sight_speed=self.sight_speed, waiting=self._waiting)

    def update(self, inp: PlannerInput) -> Plan:
        """The plan for this tick (module doc)."""
        ego, view, tracks = inp.ego, inp.lane, inp.tracks
        dt = 0.0 if self._last_t is None else max(ego.t - self._last_t, 0.0)
        self._last_t = ego.t
        if inp.signs is not None:
            self.events.see_signs(inp.signs.signs, inp.signs.pose)
        if inp.lights:
            self.junctions.see_lights(inp.lights)
        self.inputs.update(inp.driver, ego.speed, dt)
        engaged = inp.engaged and not self.inputs.overridden
        station, lateral = self.localise(ego)
        self._waiting = self.events.waiting(station, float(self.lane.offset_at(station)),
                                            float(self.lane.width_at(station)), tracks,
                                            ego.position_sigma)
        target = self.speed_for(station)
        want = min(self.inputs.set_speed, target.limit_at_front)
        manoeuvre, motion_changes = self.motion.update(ego, want, tracks,
                                                       pull_over=inp.flat_tyre,
                                                       lane_request=inp.driver.lane_request,
                                                       v_rear=self._lowest_speed(ego.speed,
                                                                                 inp.flat_tyre))
        if manoeuvre.lane != self.lane_index:  # a lane change began, ended or was aborted
            self._keep(manoeuvre.lane)
            station, lateral = self.localise(ego)
            target = self.speed_for(station)
        if manoeuvre.speed_cap < target.speed:  # in the oncoming lane: the half-sight rule
            target = replace(target, speed=manoeuvre.speed_cap, accel=0.0,
                             binding=Binding.SIGHT)
        changes = self._update_source(ego, dt, view, self.near_junction(station),
                                      self._other_lane(view, manoeuvre), inp.health.camera)
        health = inp.health
        changes += self.sensing.apply(ego.t, sensing.transition(
            self.sensing.state, SensingInput(health.lidar, health.gnss, health.occlusion),
            self.params.sensing))
        lateral_choice = self._on_shoulder(self._path(ego, station, view, manoeuvre), dt,
                                           view, station)
        lead = self._lead(view, tracks, ego, manoeuvre, lateral_choice.camera)
        planned = PlannedSpeed(SpeedRef(target.speed, target.accel),
                               BINDING_SOURCE[target.binding])
        planned, driver = self.driver.update(
            inp.pedal, ego.speed, planned, lambda: self.speed_for(station, self.max_speed),
            dt)
        events = self.events.update(ego.t, station, ego.speed,
                                    float(self.lane.offset_at(station)),
                                    float(self.lane.width_at(station)), tracks, inp.flat_tyre,
                                    pulled_over=manoeuvre.lane == SHOULDER
                                    and manoeuvre.path is None,
                                    limit_station=self.speed_planner.front_station(station),
                                    station_sigma=ego.position_sigma)
        junction = self.junctions.update(ego.t, station, ego.speed, tracks,
                                         (float(self.lane.offset_at(station)),
                                          float(self.lane.width_at(station))))
        events = replace(events, active=events.active | junction.active,
                         stop_distance=min(events.stop_distance, junction.stop_distance))
        lead_accel = self.lead_accel.update(lead)
        set_speed = self.inputs.set_speed if engaged else 0.0  # off: ACC_OFF
        acc, acc_changes = self.acc.update(ego.t, dt, ego.speed, set_speed,
                                           target.limit_at_front, planned,
                                           _with_room(lead, manoeuvre),
                                           driver_gap=self.params.override.gap_margin
                                           if driver else None, events=events,
                                           lead_accel=lead_accel)
        self.inputs.way_clear(None if lead is None else lead.along)
        speed = self._degraded_cap(acc.speed, ego.speed, dt) if engaged else \
            self.inputs.driving(inp.driver, ego.speed)
        control, control_changes = self.control.update(
            ego.t, ego.speed, speed.ref.speed, speed.ref.accel, lead, lead_accel)
        if control.emergency:
            speed = PlannedSpeed(SpeedRef(0.0, -self.control.decel), SpeedSource.EMERGENCY)
        elif not engaged and _emergency_stopped(control_changes):  # AEB standstill hold
            self.inputs.emergency_stopped()
            speed = self.inputs.driving(inp.driver, ego.speed)
        hazard_changes = self.hazard.apply(ego.t, hazard.transition(
            self.hazard.state, HazardInput(inp.flat_tyre, self._stopping(health.lidar))))
        return Plan(
            t=ego.t,
            ego=ego,
            path=lateral_choice.path,
            target_speed=speed.ref.speed,
            target_accel=speed.ref.accel,
            speed_limit=target.limit_at_front,
            station=station,
            lateral_error=lateral,
            lane_source=self.source.state,
            lead=lead,
            acc_mode=self.acc.mode,
            motion=manoeuvre.motion,
            lane=manoeuvre.lane,
            origin_lane=manoeuvre.origin,
            control=control.state,
            hazard=self.hazard.state,
            sensing=self.sensing.state,
            speed_source=speed.source,
            changes=changes + motion_changes + acc_changes + control_changes + hazard_changes,
        )

    def _lowest_speed(self, v: float, flat: bool) -> float:
        """[m/s] the lowest speed the car plans during a lane change started now: with a
        flat tyre, FLAT's slowing at ``a_flat_plan`` over the longest change, not below its
        crawl (`planner.acc_layer`); otherwise its speed `v` [m/s]."""
        if not flat:
            return v
        c, lc = self.params.acc.control, self.params.motion.lane_change
        return max(v - c.a_flat_plan * lc.t_max, min(c.v_pull_over, v))

    def _path(self, ego: EgoState, station: float, view: LaneView | None,
              manoeuvre: Manoeuvre) -> LateralChoice:
        """The lane-change path in hand, else the camera's lane when it is seen and agrees
        with the map's lane kept (not yet re-found after a lane change: the map's), else
        the map's."""
        p = self.params
        if manoeuvre.path is not None:
            ahead = max(p.path_ahead_min, p.path_ahead_time * max(ego.speed, 0.0))
            return LateralChoice(manoeuvre.path.reference_path(
                self.lane, station, p.path_behind, ahead, p.path_spacing, self.road.length),
                camera=False)
        # the camera's lane lies between painted lines: not the shoulder (no outer line);
        # in CAMERA it is the lane kept (`_other_lane`, the lane source's input)
        if self.source.state in _CAMERA_LANE and view is not None and \
                self.lane_index != SHOULDER:
            return LateralChoice(self._camera_path(view), camera=True)
        if self.source.state is LaneSource.ACQUIRING and not self._lane_seen:
            # the pose has GNSS's error across the lane until the camera's lane corrects it
            # (`perception.localization`): hold the offset the car has, parallel to the lane
            return LateralChoice(self.path_for(ego, station, self.localise(ego)[1]),
                                 camera=False)
        return LateralChoice(self.path_for(ego, station), camera=False)

    def _on_shoulder(self, choice: LateralChoice, dt: float, view: LaneView | None,
                     station: float) -> LateralChoice:
        """With the shoulder the lane kept (on it, or on the way onto it), the path moved
        across the road by the pose's error there, which the camera's view of the
        shoulder's line tells (`planner.shoulder_line`); else the path as it is."""
        if self.lane_index != SHOULDER:
            self.shoulder_line.reset()
            return choice
        error = self.shoulder_line.update(dt, view, self.lane, station)
        return replace(choice, path=shifted(choice.path, error))

    def _other_lane(self, view: LaneView | None, manoeuvre: Manoeuvre) -> bool:
        """Whether the camera's lane is not the lane kept: its offset is more than
        ``camera_agree`` from the map's lane kept at the frame's pose (not judged during a
        lane change's path, nor on the shoulder, which has no painted lane)."""
        if view is None or manoeuvre.path is not None or self.lane_index == SHOULDER:
            return False
        _, r = self.localise(view.pose)
        return abs(view.estimate.offset - r) > self.params.camera_agree

    def _stopping(self, lidar: str | None) -> str | None:
        """Why a minimum-risk stop in lane is under way (the lane lost, the LiDAR lost), or
        None."""
        if self.sensing.state is Sensing.MINIMUM_RISK:
            return lidar if lidar is not None else "the LiDAR's scans were faulty"
        if self.source.state is LaneSource.STOP_IN_LANE:
            return "the lane is lost"
        return None

    def _update_source(self, ego: EgoState, dt: float, view: LaneView | None, junction: bool,
                       other_lane: bool, camera_fault: str | None) -> tuple[StateChange, ...]:
        t = ego.t
        if self._start is None:
            self._start = t
        if ego.speed < self.params.source.standing_speed:
            self._standing += dt  # stood through the last tick, in this state
        confidence = view.estimate.confidence if view is not None else 0.0
        since = max(self.source.since, self._start)  # ACQUIRING counts from the start
        lines, age = (view.estimate.lines, view.estimate.age + max(0.0, t - view.estimate.t)) \
            if view is not None else (0, math.inf)  # the lane dead-reckoned until now
        x = LaneSourceInput(t, confidence, since, junction, other_lane, lines, age,
                            camera_fault, self._standing)
        changes = self.source.apply(t, lane_source.transition(self.source.state, x,
                                                              self.params.source))
        if changes:
            self._standing = 0.0
        self._lane_seen = self._lane_seen or self.source.state is LaneSource.CAMERA
        return changes

    def _camera_path(self, view: LaneView) -> ReferencePath:
        p = self.params
        return camera_lane_path(view.estimate, view.pose, behind=p.path_behind,
                                ahead=p.camera_ahead, spacing=p.path_spacing)

    def _lead(self, view: LaneView | None, tracks: Sequence[Track], ego: EgoState,
              manoeuvre: Manoeuvre, camera: bool) -> Lead | None:
        """The vehicle ahead in the lane (the camera's lane when it is the path, else
        straight ahead), confirmed and held by the `LeadSelector`; through a junction, along
        the map lane kept; during a lane change (or the way back from an abort), the nearest
        ahead in the lanes the car occupies (`MotionLayer`)."""
        if manoeuvre.path is not None:
            if not manoeuvre.leads:
                self.leads.take(None)
                return None
            n = min(manoeuvre.leads, key=lambda n: n.gap)
            gap = n.gap - (n.speed - ego.speed) * max(ego.t - n.t, 0.0)  # at the track's time
            lead = Lead(n.track_id, n.t, gap, max(n.speed, 0.0), n.speed)
            self.leads.take(lead)
            return lead
        p = self.params
        if self.source.state is LaneSource.JUNCTION:  # on the map's path through the junction
            candidates = route_candidates(tracks, self.lane, self.localise(ego)[0], p.lead,
                                          p.vehicle.front_overhang)
        else:
            centre: Callable[[float], float] = _straight_ahead
            if view is not None and camera:
                centre = far_centre(view.estimate.centre_y, view.estimate.heading_error,
                                    p.camera_ahead, self._bend(view.pose))
            candidates = lane_candidates(tracks, centre, ego.heading, p.vehicle.front_overhang)
        return self.leads.select(ego.t, ego.speed, candidates)

    def _bend(self, pose: EgoState) -> Callable[[float], float]:
        """x [m] ahead -> [m] the offset (left +) of the kept map lane's centre from its
        tangent at the car's station at `pose`, for the direction the car drives
        (`far_centre`, `map_bend`). `pose` is the estimate at the camera frame's time, the
        frame the camera's lane and the tracks are in: the tangent at the car's station now
        has turned with the car since, by the yaw rate times the frame's age (R 50 m at
        45 km/h, 0.1 to 0.175 s: 0.024 to 0.042 rad, 1.4 to 2.5 m at 60 m ahead)."""
        s0 = self.localise(pose)[0]
        ahead = 1.0 if math.cos(float(self.lane.heading_at(s0)) - pose.heading) >= 0.0 \
            else -1.0
        return map_bend(self.lane, s0, ahead)

    def near_junction(self, station: float) -> bool:
        """Whether the car's centre is near or in a town junction, where the map's path is
        followed and an unseen painted lane is no fault."""
        p = self.params
        return any(j.s_stop - p.junction_before <= station <= j.s_exit + p.junction_after
                   for j in self.road.junctions)

    def _degraded_cap(self, planned: PlannedSpeed, ego_speed: float,
                      dt: float) -> PlannedSpeed:
        """With the lane lost (`planner.fsm.lane_source`) or a sensor faulty
        (`planner.fsm.sensing`), ramp the target down at a_comf to the hold / slow speed, or
        to 0 for a minimum-risk stop in lane."""
        wanted = min({LaneSource.MAP_HOLD: self.params.source.hold_speed,
                      LaneSource.STOP_IN_LANE: 0.0}.get(self.source.state, math.inf),
                     {Sensing.DEGRADED: self.params.sensing.slow_speed,
                      Sensing.MINIMUM_RISK: 0.0}.get(self.sensing.state, math.inf))
        speed = planned.ref.speed
        if math.isinf(wanted):
            self._cap = math.inf
            return planned
        a_comf = self.params.speed.a_comf
        start = min(self._cap, max(ego_speed, speed)) if math.isfinite(self._cap) else ego_speed
        self._cap = max(wanted, start - a_comf * dt)
        if self._cap < speed:
            accel = -a_comf if self._cap > wanted else 0.0
            return PlannedSpeed(SpeedRef(self._cap, accel), SpeedSource.DEGRADED)
        return planned


def _with_room(lead: Lead | None, manoeuvre: Manoeuvre) -> Lead | None:
    """The lead as the ACC is to see it: nearer by the manoeuvre's room when it is the
    stationary vehicle the car may pass (it stops that much farther back: room to pull
    out, `planner.motion_layer`)."""
    if lead is None or lead.track_id != manoeuvre.room_for:
        return lead
    return replace(lead, gap=lead.gap - manoeuvre.room)


def _straight_ahead(_x: float) -> float:
    """The lane centre when the camera's lane is not available: straight ahead."""
    return 0.0


def _emergency_stopped(changes: tuple[StateChange, ...]) -> bool:
    """Whether the control machine went from EMERGENCY_STOP to STOP in `changes`: the
    emergency braking has stopped the car."""
    return any(c.machine == "control" and c.source == ControlState.EMERGENCY_STOP.value
               and c.target == ControlState.STOP.value for c in changes)
