"""A grid town: its streets, junctions, their controls, and routes through them.

Pure geometry, no PyBullet: the scenario loader compiles each route here into a route road
(`RoadSpec`) that the HD map, the planner and the criteria use like any road; the world
builds the streets, kerbs, signs and lights from `TownLayout`.

**Grid.** The town frame is the map frame. Junction (ix, iy), ix in 0..blocks_x and iy in
0..blocks_y, stands at (ix * block, iy * block); a two-way street runs along every grid
line between neighbouring junctions (right-hand traffic, `lanes` each way, no shoulder).
A street is ``2 hw`` wide, ``hw = lanes * lane_width``; lane 0 (the kerb lane) of a
direction is centred ``a = hw - lane_width / 2`` right of the street's centre line. The
junction box is the square where two streets cross, ``hw`` each side of the centre. Its
kerb corners are rounded with radius ``KERB_RADIUS``, tangent to both street edges, so that
they end ``mouth = hw + KERB_RADIUS`` from the centre. Markings run between mouths; inside,
nothing is painted.

**Turn paths** (lane 0 to lane 0, between the mouths, where a route's `Zone.JUNCTION`
pieces start and end):

- right: a quarter circle of radius ``R = RIGHT_TURN_RADIUS`` from ``a + R`` before the
  centre, straight before and after it. The kerb corner has the path's radius: one
  concentric with the path (``lane_width / 2`` inside) would leave the rear wheels no room,
  as the front axle follows the path and the rear axle runs inside it, on radius
  ``sqrt(R^2 - L^2)`` (L the wheelbase), plus the tracking error. The equal radius leaves
  ``sqrt(2) lane_width / 2`` from the path to the kerb at the corner's middle;
- left: a quarter circle of radius ``a + mouth`` through the box;
- U-turn: straight to the centre, a half circle of radius ``a`` into the opposite lane 0,
  straight back to the mouth; the street allows it when ``a >= U_TURN_MIN_RADIUS`` (a
  margin over the car's tightest turning circle at its steering limit);
- straight: through the box.

**Control.** A junction where three or four streets meet has stop signs on every approach
or traffic lights (`TownSpec.junctions`; `mixed`: lights where ix + iy is even). A corner of
the town (two streets) is a bend, uncontrolled. Each approach has a stop line
``STOP_SETBACK`` before its mouth, and either a stop sign on its right at the line
(``SIGN_CLEARANCE`` beyond the kerb) or a light on the far right corner of the junction
facing it (``LIGHT_BEHIND_KERB`` behind the rounded kerb, ``LIGHT_HEIGHT`` high). The
east-west approaches of a junction share a signal plan; the north-south ones get theirs
half a cycle later, while the others are red (`LightTiming`); the plans of neighbouring
junctions are offset by ``ix LIGHT_OFFSET_X + iy LIGHT_OFFSET_Y`` (modulo the cycle).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from world.frames import wrap_angle
from world.hdmap import Control, Junction, LightHead, Manoeuvre, StopSign, Zone
from world.spec import FeatureSpec, RoadSpec, SegmentSpec, TownSpec, TrafficLightSpec

RIGHT_TURN_RADIUS = 6.0  # [m] lane-centre radius of a right turn
KERB_RADIUS = 6.0  # [m] a junction's rounded kerb corners
U_TURN_MIN_RADIUS = 5.0  # [m] the tightest U-turn the route planner asks of the car
STOP_SETBACK = 1.0  # [m] from the stop line to the mouth (where the kerb corner starts)
SIGN_CLEARANCE = 0.5  # [m] from the kerb to a stop sign's pole (as `world.scene.scenery`)
LIGHT_BEHIND_KERB = 1.0  # [m] a light's pole from the rounded kerb of its corner
LIGHT_HEIGHT = 3.5  # [m] the light's housing centre above the ground
LIGHT_OFFSET_X = 10.0  # [s] signal plan offset per junction along x ...
LIGHT_OFFSET_Y = 17.0  # [s] ... and along y
MIN_STREET = 10.0  # [m] of marked street a block must leave between two mouths

# compass directions: [rad] map-frame heading, grid step, and turns
HEADINGS = {"east": 0.0, "north": 0.5 * math.pi, "west": math.pi, "south": -0.5 * math.pi}
STEPS = {"east": (1, 0), "north": (0, 1), "west": (-1, 0), "south": (0, -1)}
LEFT_OF = {"east": "north", "north": "west", "west": "south", "south": "east"}
RIGHT_OF = {v: k for k, v in LEFT_OF.items()}
OPPOSITE = {"east": "west", "west": "east", "north": "south", "south": "north"}

Index = tuple[int, int]


class TownError(ValueError):
    """A route or town that cannot be built: `key` names the scenario key at fault."""

    def __init__(self, key: str, problem: str) -> None:
        super().__init__(f"{key}: {problem}")
        self.key = key
        self.problem = problem


@dataclass(frozen=True, slots=True)
class Approach:
    """The end of one street at one controlled junction, for the traffic heading in."""

    junction: Index  # (ix, iy)
    heading: str  # the direction of travel into the junction, a key of `HEADINGS`
    stop_line: tuple[float, float]  # [m] centre of the stop line (across the lanes heading in)
    stop_sign: tuple[tuple[float, float], float] | None  # ([m] pole foot, [rad] plate yaw)
    light: TrafficLightSpec | None  # its signal plan and head; `s` is 0 (not on a route)


@dataclass(frozen=True, slots=True)
class TownLayout:
    """The geometry of a `TownSpec` (module doc)."""

    spec: TownSpec

    @property
    def half_width(self) -> float:
        """[m] hw, kerb to the street's centre line."""
        return self.spec.lanes * self.spec.lane_width

    @property
    def kerb_lane(self) -> float:
        """[m] a: lane 0's centre from the street's centre line."""
        return self.half_width - 0.5 * self.spec.lane_width

    @property
    def corner_radius(self) -> float:
        """[m] the kerb corner's radius."""
        return KERB_RADIUS

    @property
    def mouth(self) -> float:
        """[m] from a junction's centre to where its kerb corners end (markings start)."""
        return self.half_width + KERB_RADIUS

    @property
    def left_turn_radius(self) -> float:
        """[m] a + mouth, the left turn's lane-centre radius."""
        return self.kerb_lane + self.mouth

    @property
    def u_turn_allowed(self) -> bool:
        """Whether lane 0 is far enough from the centre line for a U-turn (a half circle)."""
        return self.kerb_lane >= U_TURN_MIN_RADIUS

    def centre(self, j: Index) -> tuple[float, float]:
        """[m] map-frame centre of junction j."""
        return (j[0] * self.spec.block, j[1] * self.spec.block)

    def exists(self, j: Index) -> bool:
        """Whether junction j is in the grid."""
        return 0 <= j[0] <= self.spec.blocks_x and 0 <= j[1] <= self.spec.blocks_y

    def junctions(self) -> list[Index]:
        """Every junction of the grid."""
        return [(ix, iy) for ix in range(self.spec.blocks_x + 1)
                for iy in range(self.spec.blocks_y + 1)]

    def arms(self, j: Index) -> tuple[str, ...]:
        """The directions in which a street leaves junction j."""
        return tuple(h for h, (dx, dy) in STEPS.items() if self.exists((j[0] + dx, j[1] + dy)))

    def control(self, j: Index) -> Control:
        """How junction j is controlled: none at a bend (fewer than three arms), else as the
        spec says (`mixed` by the parity of ix + iy)."""
        if len(self.arms(j)) < 3:
            return Control.NONE
        kind = self.spec.junctions
        if kind == "mixed":
            kind = "traffic_lights" if (j[0] + j[1]) % 2 == 0 else "stop_signs"
        return Control(kind)

    def streets(self) -> list[tuple[Index, str]]:
        """Every street once, as (its west / south junction, "east" / "north")."""
        return [(j, h) for j in self.junctions() for h in ("east", "north") if h in self.arms(j)]

    def point(self, j: Index, heading: str, along: float, right: float) -> tuple[float, float]:
        """[m] the point `along` from junction j's centre in `heading`, `right` of that line."""
        x0, y0 = self.centre(j)
        psi = HEADINGS[heading]
        c, s = math.cos(psi), math.sin(psi)
        return (x0 + along * c + right * s, y0 + along * s - right * c)

    def signal(self, j: Index, heading: str) -> TrafficLightSpec:
        """The signal plan and head for the traffic heading into j (its `s` is 0)."""
        t = self.spec.lights
        offset = (j[0] * LIGHT_OFFSET_X + j[1] * LIGHT_OFFSET_Y) % t.cycle
        if heading in ("north", "south"):
            offset -= t.green + t.yellow + t.all_red
        corner = self.half_width + self.corner_radius * (1.0 - math.sqrt(0.5))
        corner += LIGHT_BEHIND_KERB * math.sqrt(0.5)
        x, y = self.point(j, heading, corner, corner)
        head = LightHead(x, y, LIGHT_HEIGHT, wrap_angle(HEADINGS[heading] + math.pi))
        red = t.cycle - t.green - t.yellow
        return TrafficLightSpec(0.0, t.green, t.yellow, red, offset % t.cycle, head)

    def approaches(self) -> list[Approach]:
        """Every approach of every controlled junction."""
        out = []
        for j in self.junctions():
            control = self.control(j)
            if control is Control.NONE:
                continue
            for arm in self.arms(j):
                heading = OPPOSITE[arm]
                back = -(self.mouth + STOP_SETBACK)
                line = self.point(j, heading, back, 0.5 * self.half_width)
                sign = None
                if control is Control.STOP_SIGNS:
                    pole = self.point(j, heading, back, self.half_width + SIGN_CLEARANCE)
                    sign = (pole, wrap_angle(HEADINGS[heading] + math.pi))
                light = self.signal(j, heading) if control is Control.TRAFFIC_LIGHTS else None
                out.append(Approach(j, heading, line, sign, light))
        return out

    def check(self, key: str) -> None:
        """Raise TownError if the blocks are too short for two junction mouths and a street."""
        need = 2.0 * self.mouth + MIN_STREET
        if self.spec.block < need:
            raise TownError(f"{key}.block", f"must be at least {need:g} m with {self.spec.lanes} "
                            f"lane(s) of {self.spec.lane_width:g} m, got {self.spec.block:g}")


# ---------------------------------------------------------------------------------------
# Routes
# ---------------------------------------------------------------------------------------


@dataclass(slots=True)
class _Builder:
    """Lays a route's segments one after the other, keeping its station."""

    layout: TownLayout
    segments: list[SegmentSpec]
    s: float = 0.0

    def street(self, length: float) -> None:
        """A straight street piece [m] with every lane both ways."""
        n = self.layout.spec.lanes
        self._add(length, 0.0, n, n, Zone.CITY)

    def box(self, length: float, through: bool) -> None:
        """A straight piece inside a junction: all lanes when going straight through, only
        lane 0 on the way to a turn."""
        n = self.layout.spec.lanes if through else 1
        self._add(length, 0.0, n, n if through else 0, Zone.JUNCTION)

    def arc(self, radius: float, angle: float) -> None:
        """An arc of lane 0 only: `radius` [m], `angle` [rad] > 0 turns left."""
        self._add(radius * abs(angle), math.copysign(1.0 / radius, angle), 1, 0, Zone.JUNCTION)

    def _add(self, length: float, curvature: float, lanes: int, oncoming: int,
             zone: Zone) -> None:
        # a zero-length piece (a right turn's lead-in on a wide street) is left out
        if length <= 1e-9:
            return
        w = self.layout.spec.lane_width
        self.segments.append(SegmentSpec(length, curvature, lanes, oncoming, w, 0.0, None, zone))
        self.s += length


def compile_route(layout: TownLayout, start: tuple[int, int, str],
                  route: Sequence[Manoeuvre], key: str) -> RoadSpec:
    """The route road of a car that starts in lane 0 at the mouth of junction `start[:2]`,
    heading `start[2]`, and does `route[k]` at the k-th junction it meets.

    Steps, per manoeuvre: check the junction has the street it leaves by; lay the street to
    the junction's mouth, then its turn path (`_lay_turn`); record the `Junction` and put
    its control (stop sign or light, at the stop line) among the features. The route ends
    with a street to the stop line of the junction after the last. `key` (`ego`,
    `actors.3`) names the route in errors (`TownError`)."""
    j, heading = (start[0], start[1]), start[2]
    if not layout.exists(j):
        raise TownError(f"{key}.start", f"no junction {j} in this town")
    if heading not in layout.arms(j):
        raise TownError(f"{key}.start", f"no street leaves junction {j} heading {heading}")
    b = _Builder(layout, [])
    origin = (*layout.point(j, heading, layout.mouth, layout.kerb_lane), HEADINGS[heading])
    features: list[FeatureSpec] = []
    junctions: list[Junction] = []
    for k, manoeuvre in enumerate(route):
        nxt = (j[0] + STEPS[heading][0], j[1] + STEPS[heading][1])
        _check_manoeuvre(layout, nxt, heading, manoeuvre, f"{key}.route.{k}")
        b.street(layout.spec.block - 2.0 * layout.mouth)
        s_enter = b.s
        new_heading = _lay_turn(b, manoeuvre, heading)
        junction = _junction(layout, nxt, heading, manoeuvre, s_enter, b.s)
        junctions.append(junction)
        features += _controls(layout, junction, heading)
        j, heading = nxt, new_heading
    b.street(layout.spec.block - 2.0 * layout.mouth - STOP_SETBACK)
    return RoadSpec(tuple(b.segments), layout.spec.speed_limit, tuple(features),
                    origin=origin, junctions=tuple(junctions))


def _check_manoeuvre(layout: TownLayout, j: Index, heading: str, manoeuvre: Manoeuvre,
                     key: str) -> None:
    out = {Manoeuvre.STRAIGHT: heading, Manoeuvre.LEFT: LEFT_OF[heading],
           Manoeuvre.RIGHT: RIGHT_OF[heading], Manoeuvre.U_TURN: OPPOSITE[heading]}[manoeuvre]
    if out not in layout.arms(j):
        raise TownError(key, f"{manoeuvre.value} at junction {j} (heading {heading}): no street "
                             f"leaves it heading {out}")
    if manoeuvre is Manoeuvre.U_TURN and not layout.u_turn_allowed:
        raise TownError(key, f"u_turn at junction {j}: the street is too narrow (lane 0 "
                             f"{layout.kerb_lane:g} m from its centre line, a U-turn needs "
                             f"{U_TURN_MIN_RADIUS:g} m: 2 lanes of 3.5 m a direction)")


def _lay_turn(b: _Builder, manoeuvre: Manoeuvre, heading: str) -> str:
    """Lay the junction's pieces (mouth to mouth); returns the heading after it."""
    layout = b.layout
    if manoeuvre is Manoeuvre.STRAIGHT:
        b.box(2.0 * layout.mouth, through=True)
        return heading
    if manoeuvre is Manoeuvre.RIGHT:
        lead_in = layout.mouth - layout.kerb_lane - RIGHT_TURN_RADIUS
        b.box(lead_in, through=False)
        b.arc(RIGHT_TURN_RADIUS, -0.5 * math.pi)
        b.box(lead_in, through=False)
        return RIGHT_OF[heading]
    if manoeuvre is Manoeuvre.LEFT:
        b.arc(layout.left_turn_radius, 0.5 * math.pi)
        return LEFT_OF[heading]
    b.box(layout.mouth, through=False)
    b.arc(layout.kerb_lane, math.pi)
    b.box(layout.mouth, through=False)
    return OPPOSITE[heading]


def _junction(layout: TownLayout, j: Index, heading: str, manoeuvre: Manoeuvre,
              s_enter: float, s_exit: float) -> Junction:
    x, y = layout.centre(j)
    return Junction(j, manoeuvre, layout.control(j), s_enter - STOP_SETBACK, s_enter,
                        s_exit, x, y, HEADINGS[heading], layout.half_width)


def _controls(layout: TownLayout, junction: Junction, heading: str) -> list[FeatureSpec]:
    if junction.control is Control.STOP_SIGNS:
        return [StopSign(junction.s_stop)]
    if junction.control is Control.TRAFFIC_LIGHTS:
        return [replace(layout.signal(junction.index, heading), s=junction.s_stop)]
    return []

