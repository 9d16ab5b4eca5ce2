"""A walking pedestrian as an articulated body: a base and eight links on revolute joints,
posed by the gait law of `world.actors.shapes.humans`.

A physics body cannot change its shape every step, but an articulated one can move its
links: so the world builds a walker once from this model and, each step, sets the base's
height and the joint angles of `walker_pose`. Posed by `link_frames`, the model's parts are
where `humans.pedestrian_parts` puts them at the same phase (the same gait angles, segment
lengths and part makers; only the order of the floating-point sums differs).

Frames (metres, x forward, y left, z up):
- the body frame: the pedestrian's, on the ground at the middle of the x range its gait
  cycle sweeps (the frame of `pedestrian_parts` and of the actor's pose);
- the base frame: at the hip joints' centre, `WalkerPose.base_x` ahead of the body origin
  and `WalkerPose.base_height` above the ground, axes parallel to the body frame (the trunk
  stays upright); the base carries the torso and the head;
- each link's frame: at its joint, in its parent's frame at `origin`; at zero angles its
  axes are the parent's. A link turns about its `axis` (a unit vector in the parent's
  frame, equal in its own) by its joint angle, right-handed.

Links and joints (angles [rad]):
- `left_thigh` / `right_thigh`: hip, parent base, axis -y: the thigh's angle from the
  vertical, forward positive (hip flexion);
- `left_shank` / `right_shank`: knee, parent the thigh, at the thigh's length below the hip,
  axis +y: knee flexion (the shank turns back from the thigh);
- `left_foot` / `right_foot`: ankle, parent the shank, at the shank's length below the knee,
  axis +y: the shank's own angle from the vertical, which keeps the foot level;
- `left_arm` / `right_arm`: shoulder, parent base, axis -y: the arm's angle from the
  vertical, forward positive.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from world.actors.shapes.humans import (
    SIDES,
    Segments,
    along,
    arm_part,
    foot_part,
    gait,
    pelvis_height,
    segments,
    shank_part,
    shoulder_joint,
    sweep_centre,
    thigh_part,
    trunk_parts,
)
from world.actors.shapes.parts import BodyPart, points
from world.scene.solids import FloatArray, Vec3

BASE = "base"  # the parent name of the links on the base
LINK_NAMES = ("left_thigh", "left_shank", "left_foot", "right_thigh", "right_shank",
              "right_foot", "left_arm", "right_arm")  # the links in the model's order
FORWARD: Vec3 = (0.0, -1.0, 0.0)  # a joint axis turning a hanging segment's end forward
BACKWARD: Vec3 = (0.0, 1.0, 0.0)  # ... turning it back
Frame = tuple[FloatArray, FloatArray]  # (3, 3) rotation to the body frame, (3,) origin [m]


@dataclass(frozen=True, slots=True)
class WalkerLink:
    """One link: its joint and its convex parts."""

    name: str
    parent: str  # `BASE` or the name of an earlier link
    origin: Vec3  # [m] the joint (this link's frame origin) in the parent's frame
    axis: Vec3  # the revolute joint's unit axis in the parent's (and the link's) frame
    parts: tuple[BodyPart, ...]  # [m] in the link's own frame


@dataclass(frozen=True, slots=True)
class WalkerModel:
    """A walker of stature `height` [m]: its base's parts and its links, parents first, and
    the gait amplitude it walks with (its parts do not depend on it; its poses do)."""

    height: float  # [m] stature
    width: float | None  # [m] the shoulders' largest width, if bounded
    amplitude: float  # [-] the gait's amplitude, 0 to 1 (`humans.gait`)
    base_parts: tuple[BodyPart, ...]  # [m] in the base frame: torso and head
    links: tuple[WalkerLink, ...]

    def link(self, name: str) -> WalkerLink:
        """The link called `name` (KeyError otherwise)."""
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(f"no walker link {name!r}")


@dataclass(frozen=True, slots=True)
class WalkerPose:
    """Where a walker's base is and how its joints are turned at one gait phase."""

    base_x: float  # [m] the base frame's origin (the hip joints' centre) ahead of the body's
    base_height: float  # [m] ... above the ground
    angles: Mapping[str, float]  # [rad] each link's joint angle, by name in `LINK_NAMES` order


def _vec(a: FloatArray) -> Vec3:
    return (float(a[0]), float(a[1]), float(a[2]))


def _leg(side: str, y: float, seg: Segments) -> tuple[WalkerLink, ...]:
    zero = np.zeros(3)
    return (
        WalkerLink(f"{side}_thigh", BASE, (0.0, y, 0.0), FORWARD,
                   (thigh_part(side, zero, seg.thigh * along(0.0), seg),)),
        WalkerLink(f"{side}_shank", f"{side}_thigh", (0.0, 0.0, -seg.thigh), BACKWARD,
                   (shank_part(side, zero, seg.shank * along(0.0), seg),)),
        WalkerLink(f"{side}_foot", f"{side}_shank", (0.0, 0.0, -seg.shank), BACKWARD,
                   (foot_part(side, zero, seg),)),
    )


def _arm(side: str, s: float, seg: Segments) -> WalkerLink:
    origin = np.array([0.0, 0.0, seg.shoulder]) + shoulder_joint(seg, s)
    return WalkerLink(f"{side}_arm", BASE, _vec(origin), FORWARD,
                      (arm_part(side, np.zeros(3), seg.arm * along(0.0), seg),))


@functools.cache
def walker_model(height: float, width: float | None = None,
                 amplitude: float = 1.0) -> WalkerModel:
    """The articulated model of a walker of stature `height` [m], its shoulders (arms
    included) no wider than `width` [m] if given, walking with the gait `amplitude` [-]:
    the parts of `pedestrian_parts`."""
    seg = segments(height, width)
    links = (*_leg("left", seg.hip_y, seg), *_leg("right", -seg.hip_y, seg),
             *(_arm(side, s, seg) for side, s in SIDES))
    return WalkerModel(height, width, amplitude, trunk_parts(seg), links)


def walker_pose(height: float, phase: float, width: float | None = None,
                amplitude: float = 1.0) -> WalkerPose:
    """The pose of a walker of stature `height` [m] at gait `phase` (0 to 1, 0 = left heel
    strike) with the gait `amplitude` [-], its shoulders no wider than `width` [m] if given
    (as its model's: the width and the amplitude move the body origin, the middle of the x
    range the gait sweeps)."""
    g = gait(phase, amplitude)
    angles: dict[str, float] = {}
    for i, (side, _) in enumerate(SIDES):
        hip, knee = g.hip[i], g.knee[i]
        angles |= {f"{side}_thigh": hip, f"{side}_shank": knee, f"{side}_foot": hip - knee,
                   f"{side}_arm": g.arm[i]}
    return WalkerPose(-sweep_centre(height, width, amplitude),
                      pelvis_height(g, segments(height, None)),
                      {name: angles[name] for name in LINK_NAMES})


def axis_rotation(axis: Vec3, angle: float) -> FloatArray:
    """(3, 3) the right-handed rotation by `angle` [rad] about the unit `axis` (Rodrigues)."""
    k = np.asarray(axis, dtype=np.float64)
    cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.asarray(np.eye(3) + np.sin(angle) * cross
                      + (1.0 - np.cos(angle)) * (cross @ cross), dtype=np.float64)


def link_frames(model: WalkerModel, pose: WalkerPose) -> dict[str, Frame]:
    """Forward kinematics: each frame (`BASE` and every link) in the body frame."""
    frames: dict[str, Frame] = {
        BASE: (np.eye(3), np.array([pose.base_x, 0.0, pose.base_height]))}
    for link in model.links:
        rot, origin = frames[link.parent]
        frames[link.name] = (rot @ axis_rotation(link.axis, pose.angles[link.name]),
                             origin + rot @ np.asarray(link.origin))
    return frames


def posed_points(model: WalkerModel, pose: WalkerPose) -> dict[str, FloatArray]:
    """(P, 3) [m] each part's points in the body frame, by part name."""
    frames = link_frames(model, pose)
    owned = [(BASE, p) for p in model.base_parts]
    owned += [(link.name, p) for link in model.links for p in link.parts]
    out: dict[str, FloatArray] = {}
    for frame, part in owned:
        rot, origin = frames[frame]
        out[part.name] = np.asarray(points(part) @ rot.T + origin, dtype=np.float64)
    return out


SWEEP_PHASES = 64  # [-] phases a gait cycle is sampled at for its swept extent (0 and 0.5,
#   the hips' extremes, among them)


@functools.cache
def swept_half_extents(height: float, width: float | None = None,
                       amplitude: float = 1.0) -> tuple[float, float]:
    """[m] the largest |x| and |y| of a walker's parts in its body frame over a gait cycle
    with the gait `amplitude` [-] (sampled at `SWEEP_PHASES` phases): the half footprint its
    walk sweeps."""
    model = walker_model(height, width, amplitude)
    half = np.zeros(2)
    for k in range(SWEEP_PHASES):
        posed = posed_points(model, walker_pose(height, k / SWEEP_PHASES, width, amplitude))
        for pts in posed.values():
            half = np.maximum(half, np.abs(pts[:, :2]).max(axis=0))
    return float(half[0]), float(half[1])
