"""A painted stop line across the ego lane, from the front camera's pixels.

Steps, on the bird's-eye view of the camera's paint mask (`perception.lanes.lane_mask`
warped by `perception.birdseye`, before the lane finder drops the runs across the view):

1. for each BEV row (forward distance x [m] from the car's centre), the fraction of cells
   painted across the middle ``span`` of the lane the camera sees (its centre ``centre_y(x)``
   and width from the `LaneEstimate`);
2. rows painted across at least ``min_fraction`` are a band across the lane; the nearest
   run of such rows, ``min_depth`` .. ``max_depth`` deep along x, is a stop line (a 0.3 m
   bar; a zebra's stripes run along the lane and cover about half of it; a vehicle's face
   smears metres along the view);
3. its near edge, the run's smallest x, is returned.

Only the distance is measured here; which of the map's stop lines it is, and what it says
about the car's station, is the localiser's (`perception.localization`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from perception.birdseye import BirdseyeView
from perception.lanes import LaneParams, lane_mask
from perception.messages import LaneEstimate
from world.frames import CameraFrame, CameraInfo


@dataclass(frozen=True, slots=True)
class StopLineParams:
    lanes: LaneParams = field(default_factory=LaneParams)  # the mask and the BEV grid
    span: float = 0.6  # [-] the middle part of the lane's width that must be painted
    min_fraction: float = 0.8  # [-] of the span's cells painted in a row of the band
    min_depth: float = 0.15  # [m] a stop line is 0.3 m along the lane
    max_depth: float = 0.6  # [m]
    min_x: float = 6.0  # [m] nearest forward distance looked at (the view starts at 5 m)
    max_x: float = 17.0  # [m] farthest: beyond, a 0.3 m bar is too thin in a 640 x 480 frame


class StopLineDetector:
    """The near edge of a stop line across the lane, in one camera frame."""

    def __init__(self, camera: CameraInfo, params: StopLineParams | None = None) -> None:
        self.camera = camera
        self.params = params if params is not None else StopLineParams()
        self.view = BirdseyeView(camera, self.params.lanes.grid)

    def detect(self, frame: CameraFrame, lane: LaneEstimate) -> float | None:
        """[m] forward distance from the car's centre to the near edge of a stop line across
        ``lane`` (the lane estimate of this frame), or None."""
        p = self.params
        grid = p.lanes.grid
        mask = self.view.warp(lane_mask(np.ascontiguousarray(self.view.crop(frame.rgb)),
                                        p.lanes)) >= p.lanes.mask_min_coverage
        rows = np.arange(mask.shape[0])
        x = grid.row_to_x(rows)
        keep = (x >= p.min_x) & (x <= p.max_x)
        rows, x = rows[keep], x[keep]
        half = 0.5 * p.span * lane.width
        centre = np.array([lane.centre_y(float(v)) for v in x])
        col_lo = np.clip(np.ceil(grid.y_to_col(centre + half)), 0, mask.shape[1] - 1).astype(int)
        col_hi = np.clip(np.floor(grid.y_to_col(centre - half)), 0, mask.shape[1] - 1)
        col_hi = col_hi.astype(int)
        painted = np.cumsum(mask, axis=1, dtype=np.int32)
        counts = painted[rows, col_hi] - painted[rows, col_lo] + mask[rows, col_lo]
        width = np.maximum(col_hi - col_lo + 1, 1)
        band = (counts / width >= p.min_fraction) & (col_hi > col_lo)
        return _nearest_run(x[band], grid.resolution, p.min_depth, p.max_depth)


def _nearest_run(x: np.ndarray, step: float, min_depth: float, max_depth: float) -> float | None:
    """The smallest x of the nearest run of consecutive rows (``step`` [m] apart) whose
    depth is within [min_depth, max_depth]; None if there is none."""
    if len(x) == 0:
        return None
    xs = np.sort(x)
    breaks = np.flatnonzero(np.diff(xs) > 1.5 * step)
    starts = np.concatenate(([0], breaks + 1))
    ends = np.concatenate((breaks, [len(xs) - 1]))
    for a, b in zip(starts, ends, strict=True):
        depth = xs[b] - xs[a] + step
        if min_depth <= depth <= max_depth:
            return float(xs[a] - 0.5 * step)
    return None
