"""The lane-keeping path from the camera's lane estimate (ICCAS Fig. 4a).

The estimate is the lane centre in the vehicle frame (x forward, y left, [m]) at the camera
frame's time, y(x) = -offset - tan(heading_error) x + curvature x^2 / 2. The path samples
it every ``spacing`` metres of x, with heading ``pose.heading + atan(y'(x))`` [rad] and
curvature ``curvature / (1 + y'^2)^1.5`` [1/m]. The stack's pose estimate AT THAT TIME
places it in the map frame, so the path stays where the lane is while the car moves on
(the frame is one sensor period old when it arrives): the lateral reference is the camera's,
the pose estimate only carries it over the car's own motion since the frame.
"""

from __future__ import annotations

import math

import numpy as np

from perception.messages import EgoState, LaneEstimate
from planner.messages import ReferencePath


def camera_lane_path(estimate: LaneEstimate, pose: EgoState, *, behind: float, ahead: float,
                     spacing: float) -> ReferencePath:
    """The lane centre from ``behind`` [m] behind to ``ahead`` [m] ahead of the car's centre
    at the frame's time, every ``spacing`` [m] along x, in the map frame."""
    x = np.arange(-behind, ahead + 0.5 * spacing, spacing)
    slope = -math.tan(estimate.heading_error)
    y = -estimate.offset + slope * x + 0.5 * estimate.curvature * x * x
    dy = slope + estimate.curvature * x
    c, s = math.cos(pose.heading), math.sin(pose.heading)
    xy = np.column_stack([pose.x + c * x - s * y, pose.y + s * x + c * y])
    heading = pose.heading + np.arctan(dy)
    curvature = estimate.curvature / (1.0 + dy * dy) ** 1.5
    return ReferencePath(xy=xy, heading=heading, curvature=curvature)
