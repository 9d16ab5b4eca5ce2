"""People: a walking pedestrian as a function of its gait phase, and a seated rider.

Segment lengths are shares of the stature H (Drillis and Contini's proportions, as tabled in
D. A. Winter, "Biomechanics and Motor Control of Human Movement", ch. 4): shoulder 0.818 H,
hip joint 0.530 H, knee 0.285 H, ankle 0.039 H, upper arm 0.186 H, forearm 0.146 H, hand
0.108 H, shoulder width 0.259 H, hip width 0.191 H, foot length 0.152 H.

The gait (ISO 19206-2's articulated-leg pedestrian targets swing their legs at the hip and
bend the knee of the swinging leg): over one cycle, phase 0 -> 1, the left hip angle is
``A cos(2 pi phase)`` (forward positive) and the right one its opposite; the leg whose hip
angle is decreasing stands straight, the other bends its knee by ``K |sin(2 pi phase)|``;
the arms swing opposite to the legs by ``ARM_SWING`` of the hip angle. The pelvis rides at
the height that puts the lower foot on the ground, so at phase 0 and 0.5 (double support,
legs at +-A) both feet are on the ground, and at 0.25 and 0.75 (mid stance: the standing
leg vertical) the head is at the full stature. The stride (2 A of hip swing) is bounded by
the targets' published envelope (0.60 m long for the EPTa): `HIP_SWING` and `KNEE_BEND`
are the largest round figures whose every phase stays inside it, smaller than a free
walker's (about 20 deg and 60 deg). The phase advances with the distance walked, one cycle
per `stride_length` (`phase_after`).

A walker whose box is shorter than its full gait sweeps keeps its stature and walks with a
smaller gait: one `amplitude` factor in [0, 1] scales the hip swing, the knee bend and (as
the arms follow the hips) the arm swing; the stride scales with the hip swing's sine, so the
feet do not slide more than at the full gait. Every function of the gait takes it (1: the
full gait).

`gait`, `segments`, `pelvis_height` and the part makers are the one law that both
`pedestrian_parts` (the walker's parts at one phase, in one frame) and the articulated model
of `world.actors.shapes.walker` (the same parts on links, posed by joint angles) use.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from world.actors.shapes.parts import BodyPart, hull, points, strut
from world.scene.solids import Vec3

SHOULDER, HIP, KNEE, ANKLE = 0.818, 0.530, 0.285, 0.039  # [-] heights, shares of stature
UPPER_ARM, FOREARM, HAND = 0.186, 0.146, 0.108  # [-] lengths, shares of stature
NECK = 0.065  # [-] the neck's breadth, share of stature (a neck girth of about 0.35 m at a
#   stature of 1.70 m: 0.35 / pi / 1.70)
SHOULDER_WIDTH, HIP_WIDTH, FOOT = 0.259, 0.191, 0.152  # [-] shares of stature
HIP_SWING = math.radians(8.0)  # [rad] A: the hip angle's amplitude
KNEE_BEND = math.radians(20.0)  # [rad] K: the swinging knee's largest flexion
ARM_SWING = 1.0  # [-] shoulder angle per hip angle (opposite side)
HEEL = 0.25  # [-] share of the foot behind the ankle
SWEEP_SAMPLES = 64  # [-] gait phases sampled for the sweep's centre
SIDES = (("left", 1.0), ("right", -1.0))  # the body's sides and the sign of their y


def _limb(h: float) -> float:
    """[m] the radius of a limb's prism for stature `h` [m]."""
    return 0.028 * h


@dataclass(frozen=True, slots=True)
class Gait:
    """The joint angles at one gait phase, each (left, right) [rad]."""

    hip: tuple[float, float]  # [rad] thigh from the vertical, forward positive
    knee: tuple[float, float]  # [rad] knee flexion (the shank turns back from the thigh)
    arm: tuple[float, float]  # [rad] arm from the vertical, forward positive


def gait(phase: float, amplitude: float = 1.0) -> Gait:
    """The gait law's joint angles at `phase` (0 to 1, 0 = left heel strike), the hip swing,
    knee bend and arm swing scaled by `amplitude` [-] (0 to 1)."""
    c, s = math.cos(2 * math.pi * phase), math.sin(2 * math.pi * phase)
    a, k = HIP_SWING * amplitude, KNEE_BEND * amplitude
    left, right = a * c, -a * c
    # the leg swinging forward (hip angle increasing) bends its knee
    bend_left = k * abs(s) if s < 0 else 0.0
    bend_right = k * abs(s) if s > 0 else 0.0
    return Gait((left, right), (bend_left, bend_right), (-ARM_SWING * left, -ARM_SWING * right))


@dataclass(frozen=True, slots=True)
class Segments:
    """A walker's segment lengths and joint places [m] for its stature and width."""

    height: float  # [m] stature
    limb: float  # [m] a limb prism's circumradius
    thigh: float  # [m] hip joint to knee
    shank: float  # [m] knee to ankle
    ankle: float  # [m] ankle joint above the sole
    foot: float  # [m] heel to toe
    hip_y: float  # [m] each hip joint off the centre plane
    half_shoulder: float  # [m] half the shoulders' width (arms included)
    shoulder: float  # [m] the shoulder line above the hip joints
    arm: float  # [m] shoulder joint to the end of the arm's prism


def segments(height: float, width: float | None) -> Segments:
    """The segments of a walker of stature `height` [m], shoulders no wider than `width`
    [m] if given."""
    h = height
    r = _limb(h)
    half = 0.5 * SHOULDER_WIDTH * h
    if width is not None:
        half = min(half, 0.5 * width)
    return Segments(h, r, (HIP - KNEE) * h, (KNEE - ANKLE) * h, ANKLE * h, FOOT * h,
                    0.5 * HIP_WIDTH * h - 1.2 * r, half, (SHOULDER - HIP) * h,
                    (UPPER_ARM + FOREARM + 0.6 * HAND) * h - r)


def along(angle: float) -> np.ndarray:
    """The unit vector down a segment at `angle` [rad] from the vertical, forward positive."""
    return np.array([math.sin(angle), 0.0, -math.cos(angle)])


def thigh_part(name: str, hip: np.ndarray, knee: np.ndarray, seg: Segments) -> BodyPart:
    """A thigh from the hip joint to the knee [m]."""
    return strut(f"{name}_thigh", "cloth", tuple(hip), tuple(knee), 1.2 * seg.limb)


def shank_part(name: str, knee: np.ndarray, ankle: np.ndarray, seg: Segments) -> BodyPart:
    """A shank from the knee to the ankle joint [m]."""
    return strut(f"{name}_shank", "cloth", tuple(knee), tuple(ankle), seg.limb)


def foot_part(name: str, ankle: np.ndarray, seg: Segments) -> BodyPart:
    """A level foot under the ankle joint `ankle` [m], its sole `seg.ankle` below it."""
    r = seg.limb
    sole = ankle[2] - seg.ankle
    y = ankle[1]
    return strut(f"{name}_foot", "trim", (ankle[0] - HEEL * seg.foot, y, sole + 0.5 * r),
                 (ankle[0] + (1 - HEEL) * seg.foot, y, sole + 0.5 * r), 0.5 * r, sides=4)


def arm_part(side: str, top: np.ndarray, hand: np.ndarray, seg: Segments) -> BodyPart:
    """An arm from its shoulder joint `top` to the hand's end `hand` [m]."""
    return strut(f"{side}_arm", "cloth", tuple(top), tuple(hand), seg.limb)


def _leg(name: str, hip: np.ndarray, thigh_angle: float, knee_bend: float,
         seg: Segments) -> list[BodyPart]:
    """Thigh, shank and a level foot from the hip joint `hip` [m]; angles [rad] from the
    vertical, forward positive."""
    knee = hip + seg.thigh * along(thigh_angle)
    ankle = knee + seg.shank * along(thigh_angle - knee_bend)
    return [thigh_part(name, hip, knee, seg), shank_part(name, knee, ankle, seg),
            foot_part(name, ankle, seg)]


def _reach(thigh_angle: float, knee_bend: float, h: float) -> float:
    """[m] how far below the hip joint the leg's sole is."""
    shank_angle = thigh_angle - knee_bend
    return ((HIP - KNEE) * h * math.cos(thigh_angle) + (KNEE - ANKLE) * h * math.cos(shank_angle)
            + ANKLE * h - (0.5 - 0.25 * math.sqrt(2)) * _limb(h))


def pelvis_height(g: Gait, seg: Segments) -> float:
    """[m] the hip joints' height that puts the lower sole on the ground."""
    return max(_reach(g.hip[0], g.knee[0], seg.height), _reach(g.hip[1], g.knee[1], seg.height))


def shoulder_joint(seg: Segments, side: float) -> np.ndarray:
    """[m] the shoulder joint of the left (`side` 1) or right (-1) arm from the middle of
    the shoulder line."""
    return np.array([0.0, side * (seg.half_shoulder - seg.limb), -seg.limb])


def _upper(seg: Segments, pelvis: float, arm_angles: tuple[float, float],
           lean: float = 0.0) -> list[BodyPart]:
    """Torso, head and arms over a hip joint centre at height `pelvis` [m] (x = 0), the torso
    leaning forward by `lean` [rad]; arms hang at `arm_angles` [rad] (left, right)."""
    h = seg.height
    up = np.array([math.sin(lean), 0.0, math.cos(lean)])
    base = np.array([0.0, 0.0, pelvis])
    shoulder = base + seg.shoulder * up
    depth = 0.06 * h
    torso = [(base + np.array([dx, s * HIP_WIDTH * h / 2, 0.0])) for dx in (-depth, depth)
             for s in (1, -1)]
    torso += [(shoulder + np.array([dx, s * seg.half_shoulder, 0.0])) for dx in (-depth, depth)
              for s in (1, -1)]
    neck = base + (1.0 - HIP - 0.13) * h * up
    head = points(strut("head", "skin", tuple(neck), tuple(neck + 0.13 * h * up), 0.05 * h,
                        sides=8))
    # the neck joins the head to the shoulder line: a body's silhouette has no gap there
    throat = points(strut("neck", "skin", tuple(shoulder), tuple(neck), 0.5 * NECK * h, sides=8))
    parts = [hull("torso", "cloth", np.array(torso)),
             hull("head", "skin", np.vstack([head, throat]))]
    for (side, s), angle in zip(SIDES, arm_angles, strict=True):
        top = shoulder + shoulder_joint(seg, s)
        parts.append(arm_part(side, top, top + seg.arm * along(angle), seg))
    return parts


def trunk_parts(seg: Segments) -> tuple[BodyPart, ...]:
    """A walker's torso and head over its hip joint centre at the origin (upright)."""
    return tuple(p for p in _upper(seg, 0.0, (0.0, 0.0)) if not p.name.endswith("_arm"))


def pedestrian_parts(height: float, phase: float, width: float | None = None,
                     amplitude: float = 1.0) -> tuple[BodyPart, ...]:
    """A pedestrian of stature `height` [m] walking along +x at gait `phase` (0 to 1, 0 = left
    heel strike) with the gait `amplitude` [-], its shoulders (arms included) no wider than
    `width` [m] if given. The origin is on the ground at the middle of the x range the whole
    gait cycle sweeps (the feet reach further forward than back), so the envelope is centred
    on it."""
    shift = np.array([-sweep_centre(height, width, amplitude), 0.0, 0.0])
    return tuple(hull(p.name, p.material, points(p) + shift)
                 for p in _walker(height, phase, width, amplitude))


def swept_range(height: float, width: float | None,
                amplitude: float = 1.0) -> tuple[float, float, float]:
    """[m] the least and largest x and the largest |y| of a walker's pelvis-centred parts over
    a gait cycle (sampled at `SWEEP_SAMPLES` phases, the hips' and knees' extremes among
    them)."""
    pts = np.vstack([points(p) for k in range(SWEEP_SAMPLES)
                     for p in _walker(height, k / SWEEP_SAMPLES, width, amplitude)])
    return float(pts[:, 0].min()), float(pts[:, 0].max()), float(np.abs(pts[:, 1]).max())


@functools.cache
def sweep_centre(height: float, width: float | None, amplitude: float = 1.0) -> float:
    """[m] the middle of the x range a walker's pelvis-centred parts sweep over a cycle."""
    lo, hi, _ = swept_range(height, width, amplitude)
    return 0.5 * (lo + hi)


def stride_length(height: float, amplitude: float = 1.0) -> float:
    """[m] the distance a walker of stature `height` [m] covers in one gait cycle (two
    steps). A step is how far apart the ankles are in double support (both legs straight at
    +-`HIP_SWING`), so over each stance the pelvis moves by what the standing foot moves
    back under it: the feet do not slide over a step (within one the standing foot slides
    to and fro by up to 6 % of the leg's length peak to peak, 5 cm for a 1.80 m walker, as
    the hip angle is a cosine of the phase, not the arc sine of the distance). With the gait
    `amplitude` [-] the hip swing is `amplitude * HIP_SWING` (0: no stride)."""
    seg = segments(height, None)
    return 4.0 * (seg.thigh + seg.shank) * math.sin(HIP_SWING * amplitude)


def phase_after(phase: float, distance: float, height: float, amplitude: float = 1.0) -> float:
    """The gait phase (0 to 1) of a walker of stature `height` [m] and gait `amplitude` [-] at
    `phase` once it has walked `distance` [m] (backwards if negative): one cycle per
    `stride_length` (a walker of amplitude 0 stands still: its phase stays)."""
    stride = stride_length(height, amplitude)
    if stride <= 0.0:
        return phase % 1.0
    return (phase + distance / stride) % 1.0


def _walker(height: float, phase: float, width: float | None,
            amplitude: float = 1.0) -> tuple[BodyPart, ...]:
    """The walker's parts with the origin under the pelvis."""
    seg = segments(height, width)
    g = gait(phase, amplitude)
    pelvis = pelvis_height(g, seg)
    return (*_leg("left", np.array([0.0, seg.hip_y, pelvis]), g.hip[0], g.knee[0], seg),
            *_leg("right", np.array([0.0, -seg.hip_y, pelvis]), g.hip[1], g.knee[1], seg),
            *_upper(seg, pelvis, g.arm))


def rider_parts(stature: float, seat: Vec3, feet: tuple[Vec3, Vec3],
                hands: tuple[Vec3, Vec3], lean: float) -> tuple[BodyPart, ...]:
    """A rider of `stature` [m] sitting with the hip joints over `seat` [m], the soles on
    `feet`, the hands on `hands` (left, right), the torso leaning forward `lean` [rad]."""
    seg = segments(stature, None)
    h, r = stature, seg.limb
    parts: list[BodyPart] = []
    hip0 = np.asarray(seat, dtype=np.float64)
    for (side, s), foot in zip(SIDES, feet, strict=True):
        hip = hip0 + np.array([0.0, s * seg.hip_y, 0.0])
        ankle = np.asarray(foot, dtype=np.float64) + np.array([0.0, 0.0, ANKLE * h])
        knee = _knee(hip, ankle, seg.thigh, seg.shank)
        parts += [thigh_part(side, hip, knee, seg), shank_part(side, knee, ankle, seg)]
    upper = _upper(seg, 0.0, (0.0, 0.0), lean)
    shift = hip0
    for part in upper:
        if part.name.endswith("_arm"):
            continue
        parts.append(hull(part.name, part.material, points(part) + shift))
    shoulder = hip0 + seg.shoulder * np.array([math.sin(lean), 0.0, math.cos(lean)])
    for (side, s), hand in zip(SIDES, hands, strict=True):
        top = shoulder + shoulder_joint(seg, s)
        parts.append(strut(f"{side}_arm", "cloth", tuple(top), hand, r))
    return tuple(parts)


def _knee(hip: np.ndarray, ankle: np.ndarray, thigh: float, shank: float) -> np.ndarray:
    """[m] the knee of a two-link leg from `hip` to `ankle`, bent forward and up."""
    d = ankle - hip
    dist = float(np.linalg.norm(d))
    if dist >= thigh + shank:
        return np.asarray(hip + d * thigh / (thigh + shank), dtype=np.float64)
    along = (thigh ** 2 - shank ** 2 + dist ** 2) / (2 * dist)
    off = math.sqrt(max(thigh ** 2 - along ** 2, 0.0))
    u = d / dist
    perp = np.array([-u[2], 0.0, u[0]])
    if perp[0] < 0:
        perp = -perp
    return np.asarray(hip + along * u + off * perp, dtype=np.float64)
