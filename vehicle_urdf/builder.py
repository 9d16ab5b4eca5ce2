"""Write the ego car's URDF from named dimensions (`CarDimensions`: the ICCAS 2020 test car).

The car: a box body with a cabin; two front steering hinges (axis z, revolute,
+-``max_steer``) to knuckles that carry the front wheels; four wheels on continuous joints
(axis y, the wheel's axle), each with a flat-tyre contact link fixed to it; fixed links for
a roof LiDAR and front, left and right cameras.

Frames (URDF/ROS): x forward, y left, z up, metres and radians. The base link's origin is the
centre of the body's footprint at wheel-centre height, midway between the axles, so the
car's "centre" (the station of the scenario format) is the base origin. Inertias are those
of solid boxes / cylinders / spheres of the given masses [kg].

`python -m vehicle_urdf` rewrites `car.urdf`; a test checks the committed file equals
`build_urdf(CarDimensions())`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

URDF_PATH = Path(__file__).with_name("car.urdf")


@dataclass(frozen=True, slots=True)
class CarDimensions:
    body_length: float = 4.8  # [m] bumper to bumper
    body_width: float = 1.6  # [m] side to side
    body_height: float = 1.45  # [m] ground to roof
    ground_clearance: float = 0.16  # [m] ground to the underbody
    wheelbase: float = 2.7  # [m] front to rear axle
    track: float = 1.40  # [m] left to right wheel centre
    wheel_radius: float = 0.33  # [m] rolling radius
    wheel_width: float = 0.21  # [m] tyre tread width
    body_mass: float = 1400.0  # [kg] sprung mass
    wheel_mass: float = 22.0  # [kg] each, with hub and brake
    knuckle_mass: float = 6.0  # [kg] each steering knuckle
    tyre_friction: float = 1.0  # [-] Coulomb friction of tyre on dry asphalt (ground has 1.0)
    tyre_stiffness: float = 300_000.0  # [N/m] vertical contact stiffness of one tyre
    tyre_damping: float = 20_000.0  # [N s/m] vertical contact damping (about critical per corner)
    flat_radius: float = 0.31  # [m] rolling radius of a flat tyre: the rim on the folded carcass
    flat_stiffness: float = 150_000.0  # [N/m] vertical contact stiffness of a flat tyre
    flat_damping: float = 20_000.0  # [N s/m] vertical contact damping of a flat tyre
    com_height: float = 0.52  # [m] ground to the sprung mass's centre of mass
    max_steer: float = 0.65  # [rad] hinge limit (road wheel), either way
    lidar_height: float = 0.12  # [m] above the roof
    front_camera_x: float = 0.75  # [m] ahead of the centre, top of the windscreen
    front_camera_height: float = 1.40  # [m] above ground
    side_camera_x: float = 0.55  # [m] ahead of the centre, at the mirrors
    side_camera_height: float = 1.10  # [m] above ground

    @property
    def total_mass(self) -> float:
        """[kg]"""
        return self.body_mass + 4 * self.wheel_mass + 2 * self.knuckle_mass


def _inertia_box(mass: float, sx: float, sy: float, sz: float) -> tuple[float, float, float]:
    k = mass / 12.0
    return k * (sy**2 + sz**2), k * (sx**2 + sz**2), k * (sx**2 + sy**2)


def _inertial(mass: float, ixx: float, iyy: float, izz: float, xyz: str = "0 0 0") -> str:
    return (
        f'    <inertial>\n      <origin xyz="{xyz}" rpy="0 0 0"/>\n'
        f'      <mass value="{mass:.4f}"/>\n'
        f'      <inertia ixx="{ixx:.4f}" ixy="0" ixz="0" iyy="{iyy:.4f}" iyz="0"'
        f' izz="{izz:.4f}"/>\n'
        "    </inertial>\n"
    )


def _box(size: tuple[float, float, float], xyz: tuple[float, float, float]) -> str:
    return (
        f'      <origin xyz="{_v(xyz)}" rpy="0 0 0"/>\n'
        f'      <geometry><box size="{_v(size)}"/></geometry>\n'
    )


def _v(values: tuple[float, ...]) -> str:
    return " ".join(f"{v:.4f}" for v in values)


def _body_link(d: CarDimensions) -> str:
    r = d.wheel_radius
    lower_h = 0.62  # [m] the lower body, from the underbody up
    lower_z = d.ground_clearance + lower_h / 2 - r
    cabin_len, cabin_h = 2.5, d.body_height - d.ground_clearance - lower_h
    cabin_z = d.ground_clearance + lower_h + cabin_h / 2 - r
    cabin_x = -0.25  # [m] the cabin sits a little aft
    ixx, iyy, izz = _inertia_box(d.body_mass, d.body_length, d.body_width, 1.0)
    lower = _box((d.body_length, d.body_width, lower_h), (0.0, 0.0, lower_z))
    cabin = _box((cabin_len, d.body_width - 0.12, cabin_h), (cabin_x, 0.0, cabin_z))
    return (
        '  <link name="base_link">\n'
        + _inertial(d.body_mass, ixx, iyy, izz, _v((0.0, 0.0, d.com_height - r)))
        + f'    <visual name="lower_body">\n{lower}      <material name="body"/>\n    </visual>\n'
        + f'    <visual name="cabin">\n{cabin}      <material name="glass"/>\n    </visual>\n'
        + f"    <collision>\n{lower}    </collision>\n"
        + f"    <collision>\n{cabin}    </collision>\n"
        + "  </link>\n"
    )


def _wheel_link(name: str, d: CarDimensions) -> str:
    """A wheel: a cylinder to look at, a sphere to roll on.

    Bullet's cylinder-plane contact jumps between edge points and chatters (the normal force
    alternates between none and very large from step to step); a sphere of the rolling
    radius gives one smooth contact point on the road. The tyre's friction and vertical
    compliance live in the URDF's <contact> block: the compliance spreads the load over all
    four wheels (a rigid four-point stance is statically indeterminate and leaves one
    diagonal unloaded).
    """
    r, w, m = d.wheel_radius, d.wheel_width, d.wheel_mass
    i_axle = 0.5 * m * r**2
    i_other = m * (3 * r**2 + w**2) / 12.0
    cyl = (
        f'      <origin xyz="0 0 0" rpy="{math.pi / 2:.6f} 0 0"/>\n'
        f'      <geometry><cylinder radius="{r:.4f}" length="{w:.4f}"/></geometry>\n'
    )
    sphere = f'      <geometry><sphere radius="{r:.4f}"/></geometry>\n'
    contact = (
        "    <contact>\n"
        f'      <lateral_friction value="{d.tyre_friction:.4f}"/>\n'
        '      <rolling_friction value="0"/>\n      <spinning_friction value="0"/>\n'
        f'      <stiffness value="{d.tyre_stiffness:.1f}"/>\n'
        f'      <damping value="{d.tyre_damping:.1f}"/>\n'
        "    </contact>\n"
    )
    return (
        f'  <link name="{name}">\n'
        + contact
        + _inertial(m, i_other, i_axle, i_other)
        + f'    <visual>\n{cyl}      <material name="tyre"/>\n    </visual>\n'
        + f"    <collision>\n{sphere}    </collision>\n"
        + "  </link>\n"
    )


def _rim_link(name: str, d: CarDimensions) -> str:
    """A wheel's flat-tyre contact: a sphere of the flat rolling radius inside the tyre's,
    fixed to the wheel (it spins with it), with the flat tyre's contact. It sits
    `wheel_radius - flat_radius` inside the tyre's sphere, clear of the road while the
    tyre holds its air; the ego body keeps its contact inert until that tyre goes flat
    (`world.ego.body`)."""
    i = RIM_MASS * d.flat_radius**2 / 5.0
    contact = (
        "    <contact>\n"
        f'      <lateral_friction value="{d.tyre_friction:.4f}"/>\n'
        '      <rolling_friction value="0"/>\n      <spinning_friction value="0"/>\n'
        f'      <stiffness value="{d.flat_stiffness:.1f}"/>\n'
        f'      <damping value="{d.flat_damping:.1f}"/>\n'
        "    </contact>\n"
    )
    sphere = f'      <geometry><sphere radius="{d.flat_radius:.4f}"/></geometry>\n'
    return (
        f'  <link name="{name}">\n'
        + contact
        + _inertial(RIM_MASS, i, i, i)
        + f"    <collision>\n{sphere}    </collision>\n"
        + "  </link>\n"
    )


def _knuckle_link(name: str, d: CarDimensions) -> str:
    i = d.knuckle_mass * 0.1**2 / 6.0
    return f'  <link name="{name}">\n' + _inertial(d.knuckle_mass, i, i, i) + "  </link>\n"


SENSOR_MASS = 0.05  # [kg] a sensor link's own mass (Bullet invents 1 kg for a bare link)
RIM_MASS = 0.05  # [kg] a flat-tyre contact link's own mass (the rim's is in the wheel's)


def _sensor_link(name: str) -> str:
    i = SENSOR_MASS * 0.05**2 / 6.0
    return f'  <link name="{name}">\n' + _inertial(SENSOR_MASS, i, i, i) + "  </link>\n"


def _joint(
    name: str,
    kind: str,
    parent: str,
    child: str,
    xyz: tuple[float, float, float],
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0),
    axis: str | None = None,
    limit: str | None = None,
) -> str:
    out = (
        f'  <joint name="{name}" type="{kind}">\n'
        f'    <parent link="{parent}"/>\n    <child link="{child}"/>\n'
        f'    <origin xyz="{_v(xyz)}" rpy="{_v(rpy)}"/>\n'
    )
    if axis is not None:
        out += f'    <axis xyz="{axis}"/>\n'
    if limit is not None:
        out += f"    {limit}\n"
    return out + "  </joint>\n"


def _rim(corner: str, d: CarDimensions) -> list[str]:
    """The flat-tyre contact link of a corner's wheel and its fixed joint (at the wheel's
    centre): `front_left_rim` on `front_left_wheel`, and so on."""
    return [_rim_link(f"{corner}_rim", d),
            _joint(f"{corner}_rim_joint", "fixed", f"{corner}_wheel", f"{corner}_rim",
                   (0.0, 0.0, 0.0))]


_MATERIALS = (
    '  <material name="body"><color rgba="0.10 0.30 0.75 1"/></material>\n'
    '  <material name="glass"><color rgba="0.15 0.18 0.22 1"/></material>\n'
    '  <material name="tyre"><color rgba="0.05 0.05 0.05 1"/></material>\n'
)


def build_urdf(d: CarDimensions) -> str:
    """The car's URDF text for dimensions `d` (deterministic: same input, same text)."""
    half_wb, half_tr = d.wheelbase / 2, d.track / 2
    steer_limit = (
        f'<limit lower="{-d.max_steer:.4f}" upper="{d.max_steer:.4f}"'
        ' effort="5000" velocity="2.0"/>'
    )
    parts = ['<?xml version="1.0"?>\n', '<robot name="avsim_car">\n', _MATERIALS, _body_link(d)]
    for side, y in (("left", half_tr), ("right", -half_tr)):
        knuckle, wheel = f"front_{side}_knuckle", f"front_{side}_wheel"
        parts += [
            _knuckle_link(knuckle, d),
            _joint(f"front_{side}_steer_joint", "revolute", "base_link", knuckle,
                   (half_wb, y, 0.0), axis="0 0 1", limit=steer_limit),
            _wheel_link(wheel, d),
            _joint(f"front_{side}_wheel_joint", "continuous", knuckle, wheel, (0.0, 0.0, 0.0),
                   axis="0 1 0"),
            *_rim(f"front_{side}", d),
        ]
    for side, y in (("left", half_tr), ("right", -half_tr)):
        wheel = f"rear_{side}_wheel"
        parts += [
            _wheel_link(wheel, d),
            _joint(f"rear_{side}_wheel_joint", "continuous", "base_link", wheel,
                   (-half_wb, y, 0.0), axis="0 1 0"),
            *_rim(f"rear_{side}", d),
        ]
    r = d.wheel_radius
    sensors = (
        ("lidar", (0.0, 0.0, d.body_height + d.lidar_height - r), (0.0, 0.0, 0.0)),
        ("camera_front", (d.front_camera_x, 0.0, d.front_camera_height - r), (0.0, 0.0, 0.0)),
        ("camera_left", (d.side_camera_x, d.body_width / 2, d.side_camera_height - r),
         (0.0, 0.0, math.pi / 2)),
        ("camera_right", (d.side_camera_x, -d.body_width / 2, d.side_camera_height - r),
         (0.0, 0.0, -math.pi / 2)),
    )
    for name, xyz, rpy in sensors:
        parts += [_sensor_link(f"{name}_link"),
                  _joint(f"{name}_joint", "fixed", "base_link", f"{name}_link", xyz, rpy)]
    parts.append("</robot>\n")
    return "".join(parts)


def write_urdf(path: Path = URDF_PATH, dims: CarDimensions | None = None) -> Path:
    """Write `build_urdf(dims)` (default dimensions if None) to `path`; the path."""
    path.write_text(build_urdf(dims or CarDimensions()))
    return path
