"""The sensor profiles: cameras, LiDAR, mounts and rates as `world.sensors.setup` documents
them (the rates from the rates table), and every sensor of the car in capture order."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace

import numpy as np
import pytest

from vehicle_urdf import URDF_PATH, read_geometry
from world.core.rates import FRAME_LATENCY, GNSS, ODOMETRY, PROFILE_SENSORS
from world.frames import SensorMount
from world.sensors.setup import Profile, SensorSetup, sensor_setup, sensor_timings
from world.spec import LidarNoiseSpec


@dataclass(frozen=True, slots=True)
class Row:
    """One row of the profile table in `world.sensors.setup`'s docstring."""

    front: tuple[int, int, float]  # width, height [px], rate [Hz]
    sides: tuple[int, int, float] | None
    columns: int


TABLE = {
    Profile.FAST: Row((640, 480, 10.0), None, 900),
    Profile.DEFAULT: Row((640, 480, 10.0), (320, 240, 2.0), 1800),
    Profile.PAPER: Row((1280, 960, 10.0), (1280, 960, 10.0), 1800),
}


def urdf_sensor_joints() -> dict[str, tuple[list[float], list[float]]]:
    """(xyz, rpy) of each fixed joint whose child is a sensor link, read from the URDF."""
    out = {}
    for joint in ET.parse(URDF_PATH).getroot().iter("joint"):
        child = joint.find("child")
        origin = joint.find("origin")
        assert child is not None
        link = child.attrib["link"]
        if link == "lidar_link" or link.startswith("camera_"):
            assert joint.attrib["type"] == "fixed" and origin is not None
            xyz = [float(v) for v in origin.attrib["xyz"].split()]
            rpy = [float(v) for v in origin.attrib.get("rpy", "0 0 0").split()]
            out[link] = (xyz, rpy)
    return out


def assert_mount(mount: SensorMount, xyz: list[float], rpy: list[float],
                 ride_height: float) -> None:
    np.testing.assert_allclose([mount.x, mount.y, mount.z],
                               [xyz[0], xyz[1], xyz[2] + ride_height], atol=1e-12)
    np.testing.assert_allclose([mount.roll, mount.pitch, mount.yaw], rpy, atol=1e-12)


@pytest.mark.parametrize("profile", list(Profile))
def test_profile_cameras_match_the_table(profile: Profile) -> None:
    setup = sensor_setup(profile)
    row = TABLE[profile]
    assert setup.profile is profile
    expected = {"front": row.front}
    if row.sides is not None:
        expected |= {"left": row.sides, "right": row.sides}
    assert setup.cameras[0].name == "front"  # front first
    assert {c.name: (c.width, c.height, setup.timing(c.name).rate.hz)
            for c in setup.cameras} == expected
    assert len(setup.cameras) == len(expected)
    for cam in setup.cameras:
        assert cam.fov_x == pytest.approx(math.radians(80.0))
        # the pinhole model agrees: the image's half width seen at the focal length is 40 deg
        assert math.degrees(math.atan(cam.cx / cam.fx)) == pytest.approx(40.0)
        assert math.tan(cam.fov_y / 2) == pytest.approx(
            math.tan(math.radians(40.0)) * cam.height / cam.width)


@pytest.mark.parametrize("profile", list(Profile))
def test_profile_lidar_is_vlp16_like(profile: Profile) -> None:
    lidar = sensor_setup(profile).lidar
    assert lidar.azimuth_steps == TABLE[profile].columns
    assert lidar.channels == 16
    np.testing.assert_allclose(np.degrees(lidar.elevations), np.arange(-15.0, 16.0, 2.0),
                               atol=1e-12)
    assert list(lidar.elevations) == sorted(lidar.elevations)  # ascending
    assert lidar.max_range == 100.0
    assert sensor_setup(profile).timing("lidar").rate.hz == 10
    assert lidar.rays == 16 * TABLE[profile].columns
    assert 360.0 / lidar.azimuth_steps == pytest.approx(0.4 if profile is Profile.FAST else 0.2)


@pytest.mark.parametrize("profile", list(Profile))
def test_mounts_are_the_urdf_sensor_joints_raised_by_the_ride_height(profile: Profile) -> None:
    joints = urdf_sensor_joints()
    ride_height = read_geometry().ride_height
    assert 0.0 < ride_height < read_geometry().wheel_radius
    setup = sensor_setup(profile)
    for cam in setup.cameras:
        assert_mount(cam.mount, *joints[f"camera_{cam.name}_link"], ride_height)
    assert_mount(setup.lidar.mount, *joints["lidar_link"], ride_height)
    # the side cameras look sideways: their optical axes are the car's left and right
    if profile is not Profile.FAST:
        np.testing.assert_allclose(setup.camera("left").mount.rotation()[:, 0], [0, 1, 0],
                                   atol=1e-4)
        np.testing.assert_allclose(setup.camera("right").mount.rotation()[:, 0], [0, -1, 0],
                                   atol=1e-4)
    np.testing.assert_allclose(setup.camera("front").mount.rotation(), np.eye(3), atol=1e-9)


def test_lidar_noise_block_is_applied() -> None:
    quiet = sensor_setup(Profile.DEFAULT)
    noise = LidarNoiseSpec(range_sigma=0.07, dropout=0.3)
    noisy = sensor_setup(Profile.DEFAULT, noise)
    assert (noisy.lidar.range_sigma, noisy.lidar.dropout) == (0.07, 0.3)
    assert (quiet.lidar.range_sigma, quiet.lidar.dropout) != (0.07, 0.3)
    # nothing else changes
    assert replace(noisy.lidar, range_sigma=quiet.lidar.range_sigma,
                   dropout=quiet.lidar.dropout) == quiet.lidar
    assert noisy.cameras == quiet.cameras
    # the scenario's default block is the LiDAR's default
    default = sensor_setup(Profile.FAST, LidarNoiseSpec())
    assert default.lidar == sensor_setup(Profile.FAST).lidar


def test_camera_lookup() -> None:
    default = sensor_setup(Profile.DEFAULT)
    assert isinstance(default, SensorSetup)
    for name in ("front", "left", "right"):
        assert default.camera(name).name == name
    assert default.camera("left").width == 320
    assert sensor_setup(Profile.PAPER).camera("right").height == 960
    fast = sensor_setup(Profile.FAST)
    assert fast.camera("front").width == 640
    for name in ("left", "right", "rear", ""):
        with pytest.raises(KeyError, match="fast"):
            fast.camera(name)
    with pytest.raises(KeyError):
        default.camera("Front")  # names are exact


@pytest.mark.parametrize("profile", list(Profile))
def test_setup_timings_are_the_profiles_entries_in_the_rates_table(profile: Profile) -> None:
    setup = sensor_setup(profile)
    names = [c.name for c in setup.cameras] + ["lidar"]
    assert [name for name, _ in setup.timings] == names  # the cameras in order, then the LiDAR
    assert dict(setup.timings) == PROFILE_SENSORS[profile.value]
    for name, timing in setup.timings:
        assert setup.timing(name) is timing
        assert timing.latency == FRAME_LATENCY  # frames reach the stack one period late
    with pytest.raises(KeyError, match=profile.value):
        setup.timing("gnss")  # on every car, not in the profile


def test_every_sensor_of_the_car_in_capture_order() -> None:
    setup = sensor_setup(Profile.DEFAULT)
    assert sensor_timings(setup) == (*setup.timings, ("gnss", GNSS), ("odometry", ODOMETRY))
    assert [n for n, _ in sensor_timings(setup)] == ["front", "left", "right", "lidar", "gnss",
                                                   "odometry"]
    assert sensor_timings(None) == (("gnss", GNSS), ("odometry", ODOMETRY))  # no profile


def test_a_profile_and_its_rates_table_entry_must_name_the_same_sensors(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from world.sensors import setup as setup_module

    table = dict(PROFILE_SENSORS)
    table["default"] = {k: v for k, v in PROFILE_SENSORS["default"].items() if k != "left"}
    monkeypatch.setattr(setup_module, "PROFILE_SENSORS", table)
    with pytest.raises(ValueError, match="profile default: the rates table has"):
        sensor_setup(Profile.DEFAULT)
    assert sensor_setup(Profile.FAST).timing("front") is PROFILE_SENSORS["fast"]["front"]
