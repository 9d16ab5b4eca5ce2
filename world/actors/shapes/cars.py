"""Cars and vans: a lower body (bumpers, bonnet, boot or load floor), a glass cabin with a
painted roof and pillars, four wheels at the wheelbase, lamps and plates.

One builder, `car_parts`, shaped by a `CarProfile` (heights in metres or as shares of the
overall height, stations as shares of the length from the front):
- saloon (three-box): a low bonnet and a boot deck either side of the cabin;
- SUV (two-box): tall, the cabin running to a near-vertical tailgate;
- small car (two-box hatchback), the Global Vehicle Target (ISO 19206-3, a hatchback);
- panel van (one-box): the windscreen at the nose, glass only in the cab, a painted load
  box behind it to the roof.
Every profile keeps the bounding box exactly the given length, width and height: the
bumpers reach x = +-length/2, the sides y = +-width/2, the roof z = height.
"""

from __future__ import annotations

from dataclasses import dataclass

from world.actors.shapes.parts import BodyPart, box, hull, mirrored, strut, wheel
from world.actors.shapes.tyres import Tyre

PILLAR = 0.045  # [m] circumradius of a pillar's prism
ROOF = 0.05  # [m] roof panel thickness
LAMP = 0.015  # [m] how far a lamp stands proud of the body's surface


@dataclass(frozen=True, slots=True)
class CarProfile:
    """The side and plan shape of a car, as shares of its length and height."""

    front_overhang: float  # [-] share of (length - wheelbase) ahead of the front axle
    sill: float  # [m] height of the lower body's underside
    bumper: float  # [-] top of the vertical bumper face, share of height
    nose: float  # [-] the bonnet's front edge, share of height
    belt: float  # [-] the waist (bonnet rear, boot deck, window sills), share of height
    tail: float  # [-] the rear edge of the boot deck / tailgate base, share of height
    screen: float  # [-] the windscreen's base, share of length from the front
    roof_front: float  # [-] the roof's front edge, share of length from the front
    roof_rear: float  # [-] the roof's rear edge
    back: float  # [-] the rear screen's base
    tumblehome: float  # [m] inset of the roof's sides from the body's sides
    cargo: float | None = None  # [-] a panel van's cab ends here: paint behind, to the roof


SALOON = CarProfile(0.48, 0.18, 0.38, 0.52, 0.62, 0.66, 0.33, 0.45, 0.73, 0.82, 0.17)
SUV = CarProfile(0.47, 0.22, 0.35, 0.50, 0.58, 0.58, 0.30, 0.42, 0.95, 0.985, 0.15)
HATCHBACK = CarProfile(0.50, 0.16, 0.36, 0.48, 0.58, 0.60, 0.29, 0.44, 0.92, 0.975, 0.15)
VAN = CarProfile(0.44, 0.20, 0.25, 0.40, 0.45, 0.45, 0.10, 0.25, 0.995, 0.999, 0.08,
                 cargo=0.32)


def car_parts(length: float, width: float, height: float, wheelbase: float, tyre: Tyre,
              p: CarProfile) -> tuple[BodyPart, ...]:
    """The parts of a car of these dimensions [m] and profile, in the body frame."""
    front = 0.5 * length - p.front_overhang * (length - wheelbase)  # [m] front axle x
    wheel_y = 0.5 * width - 0.5 * tyre.width - 0.02
    wheels = tuple(wheel(f"wheel_{n}", x, side * wheel_y, tyre.radius, tyre.width)
                   for n, (x, side) in enumerate(((front, 1), (front, -1),
                                                  (front - wheelbase, 1),
                                                  (front - wheelbase, -1))))
    return (*_lower(length, width, height, p), *_cabin(length, width, height, p),
            *_lamps(length, width, height, p), *wheels)


def _x(length: float, share: float) -> float:
    """[m] the station `share` of the length from the front."""
    return 0.5 * length - share * length


def _lower(length: float, width: float, height: float, p: CarProfile) -> list[BodyPart]:
    """The lower body as one hull: bumpers' faces, bonnet and boot decks, sides that bulge
    out to the full width between the wheel arches' tops and the waist."""
    hl, hw = 0.5 * length, 0.5 * width
    nose, tail = hl - 0.01, -hl + 0.01  # the plates stand at the very ends
    bump, belt = p.bumper * height, p.belt * height
    end_y = hw - 0.12  # plan-view rounding of the corners
    side_x = hl - 0.35
    pts = mirrored([
        (nose, end_y, p.sill + 0.08), (nose, end_y, bump),
        (hl - 0.18, end_y, p.nose * height), (hl - 0.25, end_y, p.sill),
        (tail, end_y, p.sill + 0.08), (tail, end_y, bump),
        (-hl + 0.12, end_y, p.tail * height), (-hl + 0.25, end_y, p.sill),
        (side_x, hw - 0.08, p.sill), (-side_x, hw - 0.08, p.sill),
        (side_x, hw, 0.42 * belt + 0.1), (-side_x, hw, 0.42 * belt + 0.1),
        (side_x, hw, belt - 0.06), (-side_x, hw, belt - 0.06),
        (_x(length, p.screen), hw - 0.06, belt), (_x(length, p.back), hw - 0.06, belt),
    ])
    return [hull("lower_body", "paint", pts),
            box("plate_front", "plate", (nose, -0.26, bump - 0.16), (hl, 0.26, bump - 0.05)),
            box("plate_rear", "plate", (-hl, -0.26, bump - 0.16), (tail, 0.26, bump - 0.05))]


def _cabin(length: float, width: float, height: float, p: CarProfile) -> list[BodyPart]:
    """Glass (the greenhouse), the roof panel over it and the pillars along its edges; a
    van's load box behind its cab."""
    hw = 0.5 * width
    belt, top = p.belt * height - 0.02, height - ROOF
    sill_y, roof_y = hw - 0.07, hw - p.tumblehome
    xs, xf = _x(length, p.screen), _x(length, p.roof_front)
    xr, xb = _x(length, p.roof_rear), _x(length, p.back)
    glass_rear_top, glass_rear_base = xr, xb
    parts: list[BodyPart] = []
    if p.cargo is not None:
        xc = _x(length, p.cargo)
        glass_rear_top = glass_rear_base = xc
        parts.append(hull("load_box", "paint", mirrored([
            (xc, sill_y, belt), (xb, sill_y, belt), (xc, roof_y, top), (xr, roof_y, top)])))
    parts.append(hull("glass", "glass", mirrored([
        (xs, sill_y, belt), (glass_rear_base, sill_y, belt),
        (xf, roof_y, top), (glass_rear_top, roof_y, top)])))
    parts.append(hull("roof", "paint", mirrored([
        (xf - 0.01, roof_y + 0.01, top - 0.005), (xr, roof_y + 0.01, top - 0.005),
        (xf + 0.04, roof_y - 0.02, height), (xr + 0.02, roof_y - 0.02, height)])))
    b_base = 0.5 * (xs + (glass_rear_base if p.cargo is not None else xb))
    b_top = 0.5 * (xf + glass_rear_top)
    for side, s in (("left", 1.0), ("right", -1.0)):
        low, high = s * (sill_y - 0.02), s * (roof_y - 0.01)
        parts.append(strut(f"a_pillar_{side}", "paint", (xs, low, belt), (xf, high, top),
                           PILLAR))
        parts.append(strut(f"b_pillar_{side}", "paint", (b_base, low, belt),
                           (b_top, high, top), PILLAR))
        if p.cargo is None:
            parts.append(strut(f"c_pillar_{side}", "paint", (xb, low, belt),
                               (xr + 0.02, high, top), PILLAR))
    return parts


def _lamps(length: float, width: float, height: float, p: CarProfile) -> list[BodyPart]:
    """Head and tail lamps, standing just proud of the lower body's sloping ends."""
    hl, hw = 0.5 * length, 0.5 * width
    bump, nose, tail = p.bumper * height, p.nose * height, p.tail * height
    zf, zr = 0.5 * (bump + nose), 0.5 * (bump + tail)
    # the surface's x at the lamp's mid height, on the line from the bumper's top edge
    # back to the bonnet's (boot's) edge
    xf = hl - 0.01 - (0.17 * (zf - bump) / (nose - bump)) + LAMP
    xr = -hl + 0.01 + (0.11 * (zr - bump) / (tail - bump)) - LAMP
    parts = []
    for side, s in (("left", 1.0), ("right", -1.0)):
        y0, y1 = sorted((s * (hw - 0.17), s * (hw - 0.47)))
        parts.append(box(f"head_lamp_{side}", "lamp", (xf - 0.1, y0, zf - 0.05),
                         (min(xf, hl), y1, zf + 0.05)))
        parts.append(box(f"tail_lamp_{side}", "lamp", (max(xr, -hl), y0, zr - 0.05),
                         (xr + 0.1, y1, zr + 0.05)))
    return parts
