"""Entities: vehicles, pedestrians, miscellaneous objects, controllers (OpenSCENARIO's
Vehicle, Pedestrian, MiscObject, Controller), resolved from catalogs or written inline."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class BoundingBox:
    """The box around an object; its centre relative to the object's reference point (for a
    vehicle the middle of the rear axle projected to the ground), in the object's frame
    (x forward, y left, z up)."""

    center_x: float  # [m]
    center_y: float  # [m]
    center_z: float  # [m]
    length: float  # [m] along x
    width: float  # [m] along y
    height: float  # [m] along z


@dataclass(frozen=True, slots=True)
class Axle:
    max_steering: float  # [rad] largest steering angle of its wheels
    wheel_diameter: float  # [m]
    track_width: float  # [m] between the wheels' centres
    position_x: float  # [m] ahead of the reference point
    position_z: float  # [m] above the ground


@dataclass(frozen=True, slots=True)
class Vehicle:
    name: str
    category: str  # vehicleCategory: car, van, truck, trailer, semitrailer, bus, motorbike, ...
    bbox: BoundingBox
    max_speed: float  # [m/s]
    max_accel: float  # [m/s²]
    max_decel: float  # [m/s²] (positive)
    max_accel_rate: float | None  # [m/s³] (1.2 Performance attribute), None when not given
    max_decel_rate: float | None  # [m/s³] (1.2)
    front_axle: Axle | None  # None: none (a trailer's, 1.3)
    rear_axle: Axle
    additional_axles: tuple[Axle, ...]
    mass: float | None  # [kg] (OpenSCENARIO 1.1+ attribute), None when not given
    role: str | None  # vehicleRole (1.2): none, ambulance, civil, fire, military, police, ...
    model: str  # model3d (1.1+), "" when absent
    properties: dict[str, str]  # Property name -> value, as written


@dataclass(frozen=True, slots=True)
class Pedestrian:
    name: str
    category: str  # pedestrianCategory: pedestrian, wheelchair, animal
    mass: float  # [kg]
    bbox: BoundingBox
    model: str  # model3d (1.1+) or model (1.0): a model name, "" when absent
    properties: dict[str, str]


@dataclass(frozen=True, slots=True)
class MiscObject:
    name: str
    category: str  # miscObjectCategory: obstacle, pole, tree, barrier, ...
    mass: float  # [kg]
    bbox: BoundingBox
    model: str  # model3d (1.1+), "" when absent
    properties: dict[str, str]


@dataclass(frozen=True, slots=True)
class Controller:
    name: str
    properties: dict[str, str]  # Property name -> value, as written


EntityObject = Vehicle | Pedestrian | MiscObject


@dataclass(frozen=True, slots=True)
class Entity:
    """A ScenarioObject: its object and, if assigned, its controller (None: the default
    controller, which follows the storyboard's actions)."""

    name: str
    object: EntityObject
    controller: Controller | None
