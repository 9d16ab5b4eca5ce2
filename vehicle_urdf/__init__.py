"""The ego car's URDF and the small builder that writes it from named dimensions."""

from vehicle_urdf.builder import URDF_PATH, CarDimensions, build_urdf
from vehicle_urdf.geometry import (
    SENSOR_LINKS,
    WHEELS,
    CarGeometry,
    MountPose,
    read_geometry,
    read_sensor_mounts,
)

__all__ = [
    "SENSOR_LINKS",
    "URDF_PATH",
    "WHEELS",
    "CarDimensions",
    "CarGeometry",
    "MountPose",
    "build_urdf",
    "read_geometry",
    "read_sensor_mounts",
]
