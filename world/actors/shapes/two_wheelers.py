"""Two-wheelers: a motorcycle (the catalogue's, and the Euro NCAP motorcyclist target's) and
the Euro NCAP bicyclist target, each two thin wheels, a frame of tubes, a seat and bars, and
for the targets a rider (`humans.rider_parts`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from world.actors.shapes.humans import rider_parts
from world.actors.shapes.parts import BodyPart, box, hull, mirrored, points, strut, wheel
from world.actors.shapes.tyres import Tyre

TUBE = 0.022  # [m] a bicycle frame tube's circumradius


def fit_lean(top: float, make: Callable[[float], tuple[BodyPart, ...]]) -> float:
    """[rad] the forward lean at which the rider `make(lean)` builds has its highest point
    at `top` [m] (bisection: leaning forward lowers the head)."""
    lo, hi = 0.0, math.radians(80.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if float(np.vstack([points(p) for p in make(mid)])[:, 2].max()) > top:
            lo = mid
        else:
            hi = mid
    return hi


def bicycle_parts(length: float, width: float, bars: float, wheelbase: float,
                  radius: float) -> tuple[BodyPart, ...]:
    """A bicycle: wheels of `radius` [m] at `wheelbase` [m], ends at +-length/2, bars
    `width` [m] wide with their top at `bars` [m]."""
    rear = -0.5 * length + radius
    front = rear + wheelbase
    bb = (rear + 0.43, 0.0, 0.28)  # [m] bottom bracket
    seat_top = (rear + 0.30, 0.0, bars - 0.2)
    head_top, head_low = (front - 0.22, 0.0, bars - 0.12), (front - 0.17, 0.0, bars - 0.32)
    return (
        wheel("rear_wheel", rear, 0.0, radius, 0.05),
        wheel("front_wheel", front, 0.0, radius, 0.05),
        strut("seat_tube", "metal", bb, seat_top, TUBE),
        strut("down_tube", "metal", bb, head_low, TUBE),
        strut("top_tube", "metal", seat_top, head_top, TUBE),
        strut("head_tube", "metal", head_low, head_top, TUBE),
        strut("chain_stays", "metal", (rear, 0.0, radius), bb, TUBE),
        strut("seat_stays", "metal", (rear, 0.0, radius), seat_top, TUBE),
        strut("fork", "metal", (front, 0.0, radius), head_low, TUBE),
        strut("stem", "metal", head_top, (front - 0.25, 0.0, bars - 0.03), TUBE),
        box("saddle", "trim", (seat_top[0] - 0.14, -0.08, seat_top[2]),
            (seat_top[0] + 0.12, 0.08, seat_top[2] + 0.06)),
        box("handlebar", "trim", (front - 0.28, -0.5 * width, bars - 0.04),
            (front - 0.24, 0.5 * width, bars)),
    )


def bicyclist_parts(length: float, width: float, height: float, bars: float,
                    wheelbase: float, radius: float, stature: float) -> tuple[BodyPart, ...]:
    """The bicycle and an adult of `stature` [m] riding it, head top at `height` [m]."""
    bike = bicycle_parts(length, width, bars, wheelbase, radius)
    rear = -0.5 * length + radius
    front = rear + wheelbase
    seat = (rear + 0.30, 0.0, bars - 0.14 + 0.03)
    hands = ((front - 0.26, 0.5 * width - 0.06, bars - 0.02),
             (front - 0.26, -0.5 * width + 0.06, bars - 0.02))
    feet = ((rear + 0.60, 0.09, 0.30), (rear + 0.26, -0.09, 0.30))  # pedals level
    lean = fit_lean(height, lambda a: rider_parts(stature, seat, feet, hands, a))
    rider = rider_parts(stature, seat, feet, hands, lean)
    return (*bike, *rider)


def motorcycle_parts(length: float, width: float, height: float, wheelbase: float,
                     front_tyre: Tyre, rear_tyre: Tyre, screen: bool) -> tuple[BodyPart, ...]:
    """A motorcycle: front wheel at the front end, tail to the rear end, bars `width` [m]
    wide; the top is its windscreen's (`screen`) or its bars' at `height` [m]."""
    hl = 0.5 * length
    front = hl - front_tyre.radius
    rear = front - wheelbase
    seat_z = 0.78 if height < 1.2 else 0.85  # [m] the seat's top
    bar_top = height - 0.2 if screen else height
    parts = [
        wheel("front_wheel", front, 0.0, front_tyre.radius, front_tyre.width),
        wheel("rear_wheel", rear, 0.0, rear_tyre.radius, rear_tyre.width),
        hull("engine", "metal", mirrored([(rear + 0.45, 0.2, 0.22), (front - 0.45, 0.2, 0.25),
                                          (rear + 0.4, 0.18, 0.6), (front - 0.4, 0.2, 0.65)])),
        hull("tank", "paint", mirrored([(front - 0.85, 0.16, 0.6), (front - 0.4, 0.18, 0.65),
                                        (front - 0.85, 0.12, seat_z + 0.08),
                                        (front - 0.5, 0.15, seat_z + 0.15)])),
        hull("seat", "trim", mirrored([(front - 1.35, 0.14, seat_z - 0.12),
                                       (front - 0.85, 0.15, seat_z - 0.12),
                                       (front - 1.3, 0.13, seat_z), (front - 0.9, 0.14, seat_z)])),
        hull("tail", "paint", mirrored([(rear + 0.2, 0.1, seat_z - 0.15), (-hl, 0.08,
                                                                           seat_z - 0.05),
                                        (front - 1.35, 0.12, seat_z - 0.12),
                                        (-hl, 0.06, seat_z + 0.0)])),
        strut("swingarm", "metal", (rear, 0.0, rear_tyre.radius), (rear + 0.55, 0.0, 0.4), 0.04),
        strut("fork_left", "metal", (front, 0.1, front_tyre.radius),
              (front - 0.3, 0.1, bar_top - 0.1), 0.03),
        strut("fork_right", "metal", (front, -0.1, front_tyre.radius),
              (front - 0.3, -0.1, bar_top - 0.1), 0.03),
        box("handlebar", "trim", (front - 0.38, -0.5 * width, bar_top - 0.04),
            (front - 0.34, 0.5 * width, bar_top)),
        box("head_lamp", "lamp", (front - 0.22, -0.1, bar_top - 0.3),
            (front - 0.12, 0.1, bar_top - 0.15)),
        box("tail_lamp", "lamp", (-hl, -0.06, seat_z - 0.13), (-hl + 0.06, 0.06, seat_z - 0.05)),
    ]
    if screen:
        parts.append(hull("windscreen", "glass", mirrored([
            (front - 0.28, 0.2, bar_top - 0.1), (front - 0.24, 0.2, bar_top - 0.25),
            (front - 0.42, 0.15, height), (front - 0.40, 0.15, height - 0.02)])))
    return tuple(parts)


def motorcyclist_parts(length: float, width: float, height: float, bike_height: float,
                       wheelbase: float, front_tyre: Tyre, rear_tyre: Tyre,
                       stature: float) -> tuple[BodyPart, ...]:
    """The motorcycle (bars' top at `bike_height` [m]) and an adult of `stature` [m]
    riding it, head top at `height` [m]."""
    bike = motorcycle_parts(length, width, bike_height, wheelbase, front_tyre, rear_tyre,
                            screen=False)
    front = 0.5 * length - front_tyre.radius
    seat = (front - 1.12, 0.0, 0.78 + 0.04)
    hands = ((front - 0.36, 0.5 * width - 0.06, bike_height - 0.02),
             (front - 0.36, -0.5 * width + 0.06, bike_height - 0.02))
    feet = ((front - 0.95, 0.2, 0.33), (front - 0.95, -0.2, 0.33))  # on the pegs
    lean = fit_lean(height, lambda a: rider_parts(stature, seat, feet, hands, a))
    rider = rider_parts(stature, seat, feet, hands, lean)
    return (*bike, *rider)
