"""Tyres by body: their radius and width from a typical tyre size designation.

A size designation (ISO 4000-1 / ETRTO, e.g. "215/55 R17") gives the section width in mm,
the aspect ratio (sidewall height / width, %) and the rim diameter in inches, so the
overall diameter is ``rim * 25.4 mm + 2 * width * aspect / 100``; the figures below are
that, rounded to the centimetre. A twin-tyred axle of a heavy vehicle is one cylinder as
wide as the pair.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Tyre:
    """A tyre as a cylinder."""

    radius: float  # [m] half the overall diameter
    width: float  # [m] section width (a twin pair: both and the gap)
    size: str  # the designation it is computed from


def tyre(size: str, twin: bool = False) -> Tyre:
    """The tyre of designation "W/A Rd" (section width W mm, aspect A %, rim d inches)."""
    section, rest = size.split("/")
    aspect, rim = rest.split(" R")
    width = float(section) / 1000.0
    diameter = float(rim) * 0.0254 + 2.0 * width * float(aspect) / 100.0
    return Tyre(round(0.5 * diameter, 3), round(2.0 * width + 0.03 if twin else width, 3),
                size + (" twin" if twin else ""))


TYRES: dict[str, Tyre] = {
    "small_car": tyre("175/65 R14"),
    "sedan": tyre("215/55 R17"),
    "suv": tyre("255/55 R19"),
    "van": tyre("235/65 R16"),
    "bus": tyre("275/70 R22.5"),
    "bus_rear": tyre("275/70 R22.5", twin=True),
    "rigid_truck": tyre("285/70 R19.5"),
    "rigid_truck_rear": tyre("285/70 R19.5", twin=True),
    "tractor": tyre("315/70 R22.5"),
    "tractor_rear": tyre("315/70 R22.5", twin=True),
    "trailer": tyre("385/65 R22.5"),
    "motorbike_front": tyre("120/70 R19"),
    "motorbike_rear": tyre("170/60 R17"),
}
