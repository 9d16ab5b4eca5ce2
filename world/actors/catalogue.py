"""The vehicle catalogue: NPC vehicle models with real dimensions.

A scenario's vehicle actor names one with `model:` (`avsim.scenario.model`); `type: car`
and `type: truck` without one get `DEFAULT_MODEL`. Each model is one body, a box of the
vehicle's overall length, width and height (an articulated vehicle is one rigid box). The
figures are a named vehicle's published data, rounded to the centimetre (overall length
and width without mirrors, height unladen); heavy vehicles stay within the EU maxima of
Council Directive 96/53/EC, Annex I (`EU_MAX_*`).

This module is a leaf (no PyBullet): the scenario format reads its names before anything
heavy is imported. The stack never sees it: the object detector's size priors are generic
class sizes of its own (`perception.objects`), not these boxes.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class VehicleClass(enum.Enum):
    """What a vehicle is, for scoring perception per class (`avsim.run.scoring`)."""

    CAR = "car"  # passenger cars and light vans (EU categories M1, N1)
    TRUCK = "truck"  # goods vehicles over 3.5 t (N2, N3), articulated ones included
    BUS = "bus"  # buses and coaches (M3)
    MOTORBIKE = "motorbike"  # two-wheelers (L3)


# Council Directive 96/53/EC, Annex I (as amended by (EU) 2015/719): maximum dimensions
EU_MAX_WIDTH = 2.55  # [m] (2.60 for refrigerated bodies)
EU_MAX_HEIGHT = 4.0  # [m]
EU_MAX_LENGTH_RIGID = 12.0  # [m] a motor vehicle other than a bus (a rigid truck)
EU_MAX_LENGTH_BUS = 13.5  # [m] a two-axle bus
EU_MAX_LENGTH_ARTICULATED = 16.5  # [m] an articulated vehicle (tractor + semi-trailer)


@dataclass(frozen=True, slots=True)
class VehicleModel:
    """One catalogue model: its body box and where its figures come from."""

    name: str  # snake_case, as a scenario names it
    cls: VehicleClass
    length: float  # [m] overall, bumper to bumper
    width: float  # [m] overall, without mirrors
    height: float  # [m] overall, unladen
    wheelbase: float  # [m] front axle to (first) rear axle
    mass: float  # [kg] kerb / unladen (NPC bodies are kinematic: for reference only)
    source: str  # the vehicle whose published data these are

    @property
    def half_sizes(self) -> tuple[float, float, float]:
        """[m] half length, half width, half height."""
        return 0.5 * self.length, 0.5 * self.width, 0.5 * self.height


CATALOGUE: dict[str, VehicleModel] = {m.name: m for m in (
    VehicleModel("small_car", VehicleClass.CAR, 3.60, 1.64, 1.49, 2.42, 930.0,
                 "Volkswagen up! (2011), manufacturer data: 3600 x 1641 x 1489 mm"),
    VehicleModel("sedan", VehicleClass.CAR, 4.77, 1.83, 1.46, 2.79, 1450.0,
                 "Volkswagen Passat B8 saloon (2015), manufacturer data: 4767 x 1832 x 1456 mm"),
    VehicleModel("suv", VehicleClass.CAR, 4.88, 1.98, 1.70, 2.90, 2070.0,
                 "Volkswagen Touareg III (2018), manufacturer data: 4878 x 1984 x 1702 mm"),
    VehicleModel("van", VehicleClass.CAR, 5.93, 2.02, 2.36, 3.67, 2100.0,
                 "Mercedes-Benz Sprinter panel van W907 (2018), standard roof, 3665 mm "
                 "wheelbase, manufacturer data: 5932 x 2020 x ~2360 mm"),
    VehicleModel("bus", VehicleClass.BUS, 12.14, 2.55, 3.12, 5.85, 11000.0,
                 "Mercedes-Benz Citaro O 530 solo bus, manufacturer data: "
                 "12135 x 2550 x 3120 mm"),
    VehicleModel("rigid_truck", VehicleClass.TRUCK, 10.0, 2.55, 3.60, 5.40, 8000.0,
                 "a two-axle 18 t box-body distribution truck (e.g. MAN TGM 18.290 4x2 with "
                 "a box body): typical figures, width at the EU maximum (96/53/EC)"),
    VehicleModel("semi_trailer", VehicleClass.TRUCK, 16.5, 2.55, 4.0, 3.60, 15000.0,
                 "tractor + box semi-trailer at the EU maxima of Directive 96/53/EC "
                 "(16.50 x 2.55 x 4.00 m); wheelbase: the tractor's; one rigid box"),
    VehicleModel("motorbike", VehicleClass.MOTORBIKE, 2.21, 0.95, 1.43, 1.53, 249.0,
                 "BMW R 1250 GS (2019), manufacturer data: 2207 x 953 x 1430 mm, "
                 "no rider"),
)}

# `type: car` and `type: truck` without a `model:`: the most common body of each (a
# mid-size saloon; a distribution truck, the commonest heavy goods vehicle in towns)
DEFAULT_MODEL: dict[str, str] = {"car": "sedan", "truck": "rigid_truck"}

# the classes each actor type may take a model of: `type: car` is any light vehicle (a
# motorbike included), `type: truck` any heavy one (a bus included)
TYPE_CLASSES: dict[str, tuple[VehicleClass, ...]] = {
    "car": (VehicleClass.CAR, VehicleClass.MOTORBIKE),
    "truck": (VehicleClass.TRUCK, VehicleClass.BUS),
}


def vehicle_model(name: str) -> VehicleModel:
    """The catalogue model `name` (KeyError naming the known ones otherwise)."""
    try:
        return CATALOGUE[name]
    except KeyError:
        raise KeyError(f"unknown vehicle model {name!r} "
                       f"(expected one of {', '.join(CATALOGUE)})") from None
