"""Ray fans for comparing the LiDAR casters: unit directions on a grid of elevations and
azimuths in the world frame."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def ray_fan(lowest_deg: float, highest_deg: float, rows: int,
            columns: int) -> NDArray[np.float64]:
    """(rows x columns, 3) unit directions: `rows` elevations evenly from `lowest_deg` to
    `highest_deg` [deg], each with `columns` azimuths evenly around the full circle."""
    elevation = np.radians(np.linspace(lowest_deg, highest_deg, rows))[:, None]
    azimuth = 2.0 * np.pi * np.arange(columns)[None, :] / columns
    return np.stack(np.broadcast_arrays(np.cos(elevation) * np.cos(azimuth),
                                        np.cos(elevation) * np.sin(azimuth),
                                        np.sin(elevation)), axis=-1).reshape(-1, 3)
