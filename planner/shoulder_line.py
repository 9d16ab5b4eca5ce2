"""Where the car is across the paved shoulder, from the one painted line the camera sees there.

The shoulder has one painted line, on its left: lane 0's right edge line (its right border
is no line, so the camera's lane is no lane on it, `planner.planner`). The car's pose
estimate is not corrected across the road on the shoulder (the localiser matches the
camera's lane to lanes of the car's direction only), so a GNSS bias moves it across the
shoulder by tenths of a metre over the tens of metres of a pull-over, while a 2.5 m shoulder
leaves a car about 0.3 m each side. The line the camera does see says where the car is.

Law, per camera frame while the lane kept is the shoulder: with the shoulder's width ``w``
[m] at the car's station on the map, the left line seen at ``y_L`` [m] (vehicle frame at
the frame's pose, x = 0, left +; the fit of that frame, not the lane filter's prediction)
puts the car's centre at ``r_cam = w / 2 - y_L`` from the shoulder's centre, left + (the
paint is centred on the boundary). The pose estimate at the frame's time puts it at
``r_pose``. Their difference ``e = r_pose - r_cam`` [m] is the estimate's error across the
shoulder; a path shifted by ``e`` (left +) in the map frame puts the car's true centre on
the path's intended line. A frame whose ``|e|`` exceeds ``agree`` saw another line (lane 0's
left line is a lane width farther) and is skipped. The correction is a first-order filter
toward the last frame's ``e`` with time constant ``tau``, from 0 (the path moves smoothly;
a single line's fit is noisy by some centimetres), held when no line is seen, and
forgotten when the lane kept is no longer the shoulder.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from perception.messages import LaneView
from planner.messages import ReferencePath
from world.hdmap import Lane


@dataclass(frozen=True, slots=True)
class ShoulderLineParams:
    agree: float = 0.8  # [m] the most the pose and the line may disagree across the shoulder
    #   (lane 0's left line, the other line the camera may take for the left one, is a lane
    #   width, >= 2.5 m, farther)
    tau: float = 1.0  # [s] time constant of the correction's filter

    def __post_init__(self) -> None:
        if self.agree <= 0.0 or self.tau <= 0.0:
            raise ValueError("agree and tau must be > 0")


class ShoulderLine:
    """The pose estimate's error across the shoulder [m], left +, from the camera's view of
    the shoulder's line (module docstring); 0 until a frame agrees."""

    def __init__(self, params: ShoulderLineParams | None = None) -> None:
        self.params = params or ShoulderLineParams()
        self.error = 0.0  # [m] the filtered correction, left +
        self._seen: float | None = None  # [m] e of the last frame taken
        self._t: float | None = None  # [s] that frame's time

    def reset(self) -> None:
        """Forget the correction (the lane kept is not the shoulder)."""
        self.error, self._seen, self._t = 0.0, None, None

    def update(self, dt: float, view: LaneView | None, shoulder: Lane, near: float) -> float:
        """One planner tick of ``dt`` [s]: take the camera frame of ``view`` if it is new
        and its left line agrees, then move the correction toward the last frame's ``e``
        by ``dt / tau``. ``near`` [m] is the car's station (the projection's hint). Returns
        the correction [m]."""
        e = self._frame(view, shoulder, near)
        if e is not None:
            self._seen = e
        if self._seen is not None:
            self.error += min(1.0, max(dt, 0.0) / self.params.tau) * (self._seen - self.error)
        return self.error

    def _frame(self, view: LaneView | None, shoulder: Lane, near: float) -> float | None:
        """``e`` [m] of the view's frame, or None (no new frame, no left line fitted in it,
        or one that does not agree)."""
        if view is None or view.estimate.left is None or view.estimate.age > 0.0 or (
                self._t is not None and view.estimate.t <= self._t):
            return None
        self._t = view.estimate.t
        s, r = shoulder.local_coordinates(np.array([view.pose.x, view.pose.y]), near)
        r_cam = 0.5 * float(shoulder.width_at(float(s))) - view.estimate.left.y_at(0.0)
        e = float(r) - r_cam
        return e if abs(e) <= self.params.agree else None


def shifted(path: ReferencePath, offset: float) -> ReferencePath:
    """``path`` moved ``offset`` [m] to its left (right if < 0), each point along its own
    normal; headings kept, curvatures kept (their change, of order k^2 offset, is
    negligible for tenths of a metre)."""
    if offset == 0.0 or not math.isfinite(offset):
        return path
    normal = np.stack([-np.sin(path.heading), np.cos(path.heading)], axis=1)
    return replace(path, xy=path.xy + offset * normal)
