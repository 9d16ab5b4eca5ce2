"""Read the car's geometry back from its URDF, so everyone uses the URDF's own numbers.

Frame: the base link's (x forward, y left, z up; origin at the centre of the body's
footprint, at wheel-centre height, midway between the axles). Lengths in metres, angles in
radians, masses in kilograms.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from vehicle_urdf.builder import URDF_PATH

WHEELS = ("front_left", "front_right", "rear_left", "rear_right")  # joint/link name prefixes


@dataclass(frozen=True, slots=True)
class CarGeometry:
    wheelbase: float  # [m] front to rear axle
    track: float  # [m] left to right wheel centre
    wheel_radius: float  # [m] rolling radius
    body_length: float  # [m] bumper to bumper
    body_width: float  # [m] side to side
    front_axle: float  # [m] ahead of the car's centre (base origin)
    rear_axle: float  # [m] behind the car's centre, as a positive distance
    mass: float  # [kg] total
    max_steer: float  # [rad] road-wheel hinge limit
    tyre_width: float  # [m] a tyre's tread, across
    ground_clearance: float  # [m] ground to the underbody, at the nominal wheel radius
    body_height: float  # [m] ground to the roof, at the nominal wheel radius
    tyre_stiffness: float = 300_000.0  # [N/m] vertical contact stiffness of one tyre
    tyre_damping: float = 20_000.0  # [N s/m] vertical contact damping of one tyre
    flat_radius: float = 0.31  # [m] rolling radius of a flat tyre (its rim link's sphere)
    flat_stiffness: float = 150_000.0  # [N/m] vertical contact stiffness of a flat tyre
    flat_damping: float = 20_000.0  # [N s/m] vertical contact damping of a flat tyre

    @property
    def ride_height(self) -> float:
        """[m] the base link origin's height above the ground at rest: the wheel radius less
        each tyre's static compression under a quarter of the weight."""
        return self.wheel_radius - self.mass * 9.81 / (4.0 * self.tyre_stiffness)

    @property
    def front_overhang(self) -> float:
        """[m] car centre to front bumper."""
        return self.body_length / 2


def _xyz(element: ET.Element | None) -> tuple[float, float, float]:
    if element is None:
        raise ValueError("URDF element without <origin>")
    x, y, z = (float(v) for v in element.attrib["xyz"].split())
    return x, y, z


def read_geometry(path: Path = URDF_PATH) -> CarGeometry:
    """Parse wheel joint origins, the wheel cylinder, the lower body box, all masses, the
    tyres' contact and the flat-tyre (rim) links' spheres and contact."""
    root = ET.parse(path).getroot()
    joints = {j.attrib["name"]: j for j in root.iter("joint")}
    links = {link.attrib["name"]: link for link in root.iter("link")}
    fl = _xyz(joints["front_left_steer_joint"].find("origin"))
    fr = _xyz(joints["front_right_steer_joint"].find("origin"))
    rl = _xyz(joints["rear_left_wheel_joint"].find("origin"))
    cylinder = links["front_left_wheel"].find("visual/geometry/cylinder")
    body = links["base_link"].find("visual[@name='lower_body']/geometry/box")
    body_origin = links["base_link"].find("visual[@name='lower_body']/origin")
    cabin = links["base_link"].find("visual[@name='cabin']/geometry/box")
    cabin_origin = links["base_link"].find("visual[@name='cabin']/origin")
    limit = joints["front_left_steer_joint"].find("limit")
    stiffness = links["front_left_wheel"].find("contact/stiffness")
    damping = links["front_left_wheel"].find("contact/damping")
    rim = links.get("front_left_rim")
    flat_sphere = None if rim is None else rim.find("collision/geometry/sphere")
    flat_stiffness = None if rim is None else rim.find("contact/stiffness")
    flat_damping = None if rim is None else rim.find("contact/damping")
    if (cylinder is None or body is None or cabin is None or limit is None or stiffness is None
            or damping is None or flat_sphere is None or flat_stiffness is None
            or flat_damping is None):
        raise ValueError(f"{path}: not an avsim car URDF")
    length, width, lower_height = (float(v) for v in body.attrib["size"].split())
    cabin_height = float(cabin.attrib["size"].split()[2])
    radius = float(cylinder.attrib["radius"])  # the base origin is at the wheels' centres
    mass = sum(float(m.attrib["value"]) for m in root.iter("mass"))
    return CarGeometry(
        wheelbase=fl[0] - rl[0],
        track=fl[1] - fr[1],
        wheel_radius=radius,
        body_length=length,
        body_width=width,
        front_axle=fl[0],
        rear_axle=-rl[0],
        mass=mass,
        max_steer=float(limit.attrib["upper"]),
        tyre_width=float(cylinder.attrib["length"]),
        ground_clearance=_xyz(body_origin)[2] - lower_height / 2 + radius,
        body_height=_xyz(cabin_origin)[2] + cabin_height / 2 + radius,
        tyre_stiffness=float(stiffness.attrib["value"]),
        tyre_damping=float(damping.attrib["value"]),
        flat_radius=float(flat_sphere.attrib["radius"]),
        flat_stiffness=float(flat_stiffness.attrib["value"]),
        flat_damping=float(flat_damping.attrib["value"]),
    )


@dataclass(frozen=True, slots=True)
class MountPose:
    """A sensor link's fixed joint: its origin in the base link frame."""

    xyz: tuple[float, float, float]  # [m] from the base link origin (x fwd, y left, z up)
    rpy: tuple[float, float, float]  # [rad] roll, pitch, yaw


SENSOR_LINKS = ("lidar_link", "camera_front_link", "camera_left_link", "camera_right_link")


def read_sensor_mounts(path: Path = URDF_PATH) -> dict[str, MountPose]:
    """The fixed joints of the sensor links, by child link name (`SENSOR_LINKS`)."""
    root = ET.parse(path).getroot()
    out = {}
    for joint in root.iter("joint"):
        child = joint.find("child")
        origin = joint.find("origin")
        if child is None or origin is None or child.attrib["link"] not in SENSOR_LINKS:
            continue
        r, p, y = (float(v) for v in origin.attrib.get("rpy", "0 0 0").split())
        out[child.attrib["link"]] = MountPose(_xyz(origin), (r, p, y))
    missing = set(SENSOR_LINKS) - set(out)
    if missing:
        raise ValueError(f"{path}: no fixed joint for sensor links {sorted(missing)}")
    return out
