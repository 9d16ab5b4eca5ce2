"""Heavy vehicles: a bus (a box with a glass band), a rigid truck (a forward-control cab and
a box body) and an articulated truck (a tractor's cab and a box semi-trailer as separate
parts). Forward-control cabs: the windscreen over the front axle, the front face flat.

Axle stations are typical ones for each body (front overhang; a tri-axle trailer's axles at
1.31 m spacing, the common spread-axle figure); the wheelbase is the catalogue's.
"""

from __future__ import annotations

from world.actors.shapes.parts import BodyPart, box, hull, mirrored, wheel
from world.actors.shapes.tyres import TYRES, Tyre

CAB_LENGTH = 2.25  # [m] a forward-control cab, front face to back wall
TRAILER_LENGTH = 13.6  # [m] a standard box semi-trailer's body
TRAILER_AXLE_SPACING = 1.31  # [m]


def _axle(name: str, x: float, width: float, tyre: Tyre) -> tuple[BodyPart, BodyPart]:
    """Two wheels at station x [m], their outer faces 2 cm inside the body's sides."""
    y = 0.5 * width - 0.5 * tyre.width - 0.02
    return (wheel(f"{name}_left", x, y, tyre.radius, tyre.width),
            wheel(f"{name}_right", x, -y, tyre.radius, tyre.width))


def _front_lamps(front: float, width: float, z: float) -> list[BodyPart]:
    """Head lamps and a plate on a flat front face at x = `front` [m]."""
    hw = 0.5 * width
    return [box("head_lamp_left", "lamp", (front - 0.05, hw - 0.45, z), (front, hw - 0.12,
                                                                         z + 0.14)),
            box("head_lamp_right", "lamp", (front - 0.05, -hw + 0.12, z),
                (front, -hw + 0.45, z + 0.14)),
            box("plate_front", "plate", (front - 0.05, -0.26, z - 0.2), (front, 0.26, z - 0.09))]


def _rear_lamps(rear: float, width: float, z: float) -> list[BodyPart]:
    """Tail lamps and a plate on a flat rear face at x = `rear` [m]."""
    hw = 0.5 * width
    return [box("tail_lamp_left", "lamp", (rear, hw - 0.4, z), (rear + 0.05, hw - 0.1, z + 0.12)),
            box("tail_lamp_right", "lamp", (rear, -hw + 0.1, z), (rear + 0.05, -hw + 0.4,
                                                                  z + 0.12)),
            box("plate_rear", "plate", (rear, -0.26, z + 0.02), (rear + 0.05, 0.26, z + 0.13))]


def _underrun(rear: float, width: float) -> list[BodyPart]:
    """The rear underrun bar under a box body ending at x = `rear` [m], with the tail lamps
    and the plate on its face."""
    hw = 0.5 * width
    return [box("underrun", "trim", (rear + 0.05, -hw + 0.1, 0.5), (rear + 0.4, hw - 0.1, 0.95)),
            *_rear_lamps(rear, width, 0.75)]


def _cab(front: float, width: float, floor: float, sill: float, top: float,
         roof: float) -> list[BodyPart]:
    """A forward-control cab from x = `front` [m] back `CAB_LENGTH`: painted up to the
    window `sill` [m], glass (windscreen, side windows) to `top`, a painted roof to `roof`."""
    hw, back = 0.5 * width, front - CAB_LENGTH
    return [
        hull("cab", "paint", mirrored([(front - 0.05, hw - 0.08, floor), (back, hw - 0.05, floor),
                                       (front - 0.05, hw, sill), (back, hw, sill)])),
        hull("cab_glass", "glass", mirrored([(front - 0.08, hw - 0.04, sill - 0.02),
                                             (back + 0.9, hw - 0.02, sill - 0.02),
                                             (front - 0.2, hw - 0.1, top),
                                             (back + 0.9, hw - 0.08, top)])),
        hull("cab_rear", "paint", mirrored([(back + 0.9, hw, sill - 0.02), (back, hw, sill - 0.02),
                                            (back + 0.9, hw - 0.06, top), (back, hw - 0.06, top)])),
        hull("cab_roof", "paint", mirrored([(front - 0.22, hw - 0.06, top - 0.03),
                                            (back, hw - 0.04, top - 0.03),
                                            (front - 0.5, hw - 0.25, roof),
                                            (back, hw - 0.2, roof)])),
    ]


def bus_parts(length: float, width: float, height: float, wheelbase: float) -> tuple[BodyPart, ...]:
    """A low-floor city bus: painted skirt to the window sills, a glass band all round
    (windscreen, side and rear windows) with painted pillars standing proud of it, a painted
    roof with its equipment pod."""
    hl, hw = 0.5 * length, 0.5 * width
    sill, top = 1.05, height - 0.42
    front = hl - 0.43 * (length - wheelbase)
    parts: list[BodyPart] = [
        hull("lower_body", "paint", mirrored([(hl - 0.05, hw - 0.06, 0.3), (-hl + 0.05,
                                                                            hw - 0.06, 0.3),
                                              (hl - 0.05, hw, sill), (-hl + 0.05, hw, sill)])),
        hull("glass", "glass", mirrored([(hl - 0.03, hw - 0.03, sill - 0.02),
                                         (-hl + 0.06, hw - 0.03, sill - 0.02),
                                         (hl - 0.08, hw - 0.05, top), (-hl + 0.08, hw - 0.05,
                                                                       top)])),
        hull("roof", "paint", mirrored([(hl - 0.1, hw - 0.05, top - 0.02), (-hl + 0.08,
                                                                            hw - 0.05, top - 0.02),
                                        (hl - 0.25, hw - 0.12, top + 0.12),
                                        (-hl + 0.15, hw - 0.12, top + 0.12)])),
        box("roof_pod", "paint", (-hl + 1.0, -hw + 0.35, top + 0.1), (-hl + 4.5, hw - 0.35,
                                                                      height)),
        *_front_lamps(hl, width, 0.55), *_rear_lamps(-hl, width, 0.75),
        *_axle("front", front, width, TYRES["bus"]),
        *_axle("rear", front - wheelbase, width, TYRES["bus_rear"]),
    ]
    for k in range(7):  # window pillars, evenly spaced between the ends
        x = -hl + 1.2 + k * (length - 2.4) / 6
        for side, s in (("left", 1.0), ("right", -1.0)):
            y0, y1 = sorted((s * (hw - 0.045), s * hw))
            parts.append(box(f"pillar_{k}_{side}", "paint", (x - 0.06, y0, sill - 0.02),
                             (x + 0.06, y1, top)))
    return tuple(parts)


def rigid_truck_parts(length: float, width: float, height: float,
                      wheelbase: float) -> tuple[BodyPart, ...]:
    """A two-axle box-body truck: forward-control cab, chassis rails, a box body to the
    full height."""
    hl, hw = 0.5 * length, 0.5 * width
    front = hl - 0.30 * (length - wheelbase)
    return (
        *_cab(hl, width, 0.45, 1.65, 2.55, 2.95),
        box("chassis", "trim", (-hl + 0.4, -0.45, 0.5), (hl - 0.3, 0.45, 1.0)),
        box("box_body", "paint", (-hl, -hw, 1.0), (hl - CAB_LENGTH - 0.1, hw, height)),
        box("bumper", "trim", (hl - 0.25, -hw + 0.05, 0.35), (hl - 0.06, hw - 0.05, 0.5)),
        *_front_lamps(hl, width, 0.6), *_underrun(-hl, width),
        *_axle("front", front, width, TYRES["rigid_truck"]),
        *_axle("rear", front - wheelbase, width, TYRES["rigid_truck_rear"]),
    )


def semi_trailer_parts(length: float, width: float, height: float,
                       wheelbase: float) -> tuple[BodyPart, ...]:
    """A 4x2 tractor (cab with its roof deflector, chassis) and a tri-axle box semi-trailer
    whose nose overhangs the tractor's rear axle."""
    hl, hw = 0.5 * length, 0.5 * width
    front = hl - 1.45  # [m] the tractor's front axle
    trailer_front = -hl + TRAILER_LENGTH
    first = -hl + 2.4  # [m] the trailer's last axle, from its rear
    trailer_axles = [axle for k in range(3)
                     for axle in _axle(f"trailer_axle_{k}", first + k * TRAILER_AXLE_SPACING,
                                       width, TYRES["trailer"])]
    return (
        *_cab(hl, width, 0.5, 1.8, 2.75, 3.1),
        hull("deflector", "paint", mirrored([(hl - 0.7, hw - 0.3, 3.05), (hl - CAB_LENGTH,
                                                                          hw - 0.2, 3.05),
                                             (hl - 1.4, hw - 0.25, height - 0.2),
                                             (hl - CAB_LENGTH, hw - 0.2, height - 0.2)])),
        box("tractor_chassis", "trim", (front - wheelbase - 0.9, -0.45, 0.55), (hl - 0.3, 0.45,
                                                                                1.05)),
        box("bumper", "trim", (hl - 0.25, -hw + 0.05, 0.4), (hl - 0.06, hw - 0.05, 0.55)),
        *_front_lamps(hl, width, 0.65),
        *_axle("front", front, width, TYRES["tractor"]),
        *_axle("rear", front - wheelbase, width, TYRES["tractor_rear"]),
        box("trailer_body", "paint", (-hl, -hw, 1.25), (trailer_front, hw, height)),
        box("trailer_chassis", "trim", (-hl + 0.8, -0.6, 0.95), (trailer_front - 0.3, 0.6, 1.25)),
        *_underrun(-hl, width),
        *trailer_axles,
    )
