"""Camera images between the sensing worker and the main process, through shared memory.

A pipe would pickle each image, push it through the kernel in 64 KiB pieces and unpickle it
on the other side: four copies of 3.7 MB per 1280 x 960 frame, and the worker blocked in
the send until the main process reads. Instead both processes map one file in shared memory
(``/dev/shm`` where there is one): per camera, `SLOTS` image slots used in turn, one per
request. The worker writes request j's image into slot ``j % SLOTS`` and sends only the
frame's metadata; the main process copies the image out as soon as it receives the answer.
The main process never has more than `SLOTS` requests unanswered
(`world.sensors.pipeline.ProcessSensing`), so a slot is written again only after its last
image was copied out. The file is unlinked as soon as both have mapped it.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from world.frames import CameraFrame, CameraInfo
from world.sensors.sensor import Reading

SLOTS = 4  # image slots per camera: more than the requests ever in flight (two, at 10 Hz)
_NO_PIXELS = np.zeros((0, 0, 3), dtype=np.uint8)  # the image a frame travels with


def shared_dir() -> Path:
    """Where the slot file goes: shared memory when the system has it mounted."""
    shm = Path("/dev/shm")
    return shm if shm.is_dir() and os.access(shm, os.W_OK) else Path(tempfile.gettempdir())


class FrameSlots:
    """The image slots of `cameras` in the file `path` (the creator sizes it)."""

    def __init__(self, path: Path, cameras: tuple[CameraInfo, ...], *, create: bool) -> None:
        self.path = path
        shapes = {c.name: (c.height, c.width, 3) for c in cameras}
        sizes = {name: SLOTS * h * w * d for name, (h, w, d) in shapes.items()}
        total = max(1, sum(sizes.values()))
        if create:
            with path.open("wb") as f:
                f.truncate(total)
        self._map: NDArray[np.uint8] = np.memmap(path, dtype=np.uint8, mode="r+", shape=(total,))
        self._views: dict[str, NDArray[np.uint8]] = {}
        offset = 0
        for name, shape in shapes.items():
            block = self._map[offset:offset + sizes[name]]
            self._views[name] = block.reshape(SLOTS, *shape)
            offset += sizes[name]

    def __contains__(self, sensor: str) -> bool:
        return sensor in self._views

    def put(self, request: int, reading: Reading) -> Reading:
        """The worker's side: `reading`'s image into request `request`'s slot; the reading
        to send, without its pixels."""
        frame = reading.frame
        assert isinstance(frame, CameraFrame)
        self._views[reading.sensor][request % SLOTS] = frame.rgb
        return replace(reading, frame=replace(frame, rgb=_NO_PIXELS))

    def take(self, request: int, reading: Reading) -> Reading:
        """The main process's side: `reading` with its image copied out of its slot."""
        frame = reading.frame
        assert isinstance(frame, CameraFrame)
        rgb = self._views[reading.sensor][request % SLOTS].copy()
        return replace(reading, frame=replace(frame, rgb=rgb))

    def close(self) -> None:
        """Drop the mapping (it is unmapped once no view of it is left)."""
        self._views = {}
        self._map = np.zeros(0, dtype=np.uint8)
