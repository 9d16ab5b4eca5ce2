"""Reference paths for the control tests: straights and arcs, sampled as the planner does."""

from __future__ import annotations

import math

import numpy as np

from planner.messages import ReferencePath


def straight(
    length: float, spacing: float = 0.5, heading: float = 0.0, start: tuple[float, float] = (0, 0)
) -> ReferencePath:
    """A straight from `start` [m] along `heading` [rad], `length` [m] long."""
    s = np.arange(0.0, length + 1e-9, spacing)
    xy = np.column_stack([start[0] + s * math.cos(heading), start[1] + s * math.sin(heading)])
    return ReferencePath(xy=xy, heading=np.full(len(s), heading), curvature=np.zeros(len(s)))


def straight_then_arc(
    straight_length: float, radius: float, arc_angle: float, left: bool = True, spacing: float = 0.5
) -> ReferencePath:
    """A straight along +x from the origin, then an arc of `radius` [m] over `arc_angle` [rad].

    The arc's centre is (straight_length, +-radius); with straight_length = 0 the path is a
    (partial) circle through the origin.
    """
    sign = 1.0 if left else -1.0
    s_straight = np.arange(0.0, straight_length, spacing)
    s_arc = np.arange(0.0, radius * arc_angle + 1e-9, spacing)
    a = s_arc / radius
    xy = np.concatenate(
        [
            np.column_stack([s_straight, np.zeros(len(s_straight))]),
            np.column_stack(
                [straight_length + radius * np.sin(a), sign * radius * (1.0 - np.cos(a))]
            ),
        ]
    )
    heading = np.concatenate([np.zeros(len(s_straight)), sign * a])
    curvature = np.concatenate([np.zeros(len(s_straight)), np.full(len(a), sign / radius)])
    return ReferencePath(xy=xy, heading=heading, curvature=curvature)
