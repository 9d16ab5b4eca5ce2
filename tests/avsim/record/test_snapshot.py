"""`avsim.record.snapshot` renders a recording's default blueprint at one `sim_time` with
Rerun's viewer.

A tiny `.rrd` is built here (0-5 s at 10 Hz): a 3D view with a red box and a ring of blue
points, always there, and a cyan box that exists only for 2 s <= t < 3 s; a time-series view
with a magenta line. The snapshot at T = 2.5 s must have the requested size, not be blank, and
show all four colours: the cyan box proves the time cursor sits at T (the viewer opens at the
start, and it is cleared before the end). The errors come before any viewer is started, except
the missing-Vulkan one, which is simulated with a Vulkan loader that finds no driver.

No skip when Vulkan is missing: `make setup` installs `mesa-vulkan-drivers`, so a failure here
means a broken setup. A snapshot takes ~3 s on two CPU cores.
"""

from __future__ import annotations

import uuid
from pathlib import Path

import numpy as np
import numpy.typing as npt
import PIL.Image
import psutil
import pytest
import rerun as rr
import rerun.blueprint as rrb

from avsim.record.snapshot import (
    SnapshotError,
    _rerun_executable,
    recording_time_range,
    render_snapshot,
)

END = 5.0  # [s] last sim_time of the tiny recording
RATE = 10.0  # [Hz]
AT = 2.5  # [s] snapshot time
WINDOW = (2.0, 3.0)  # [s] the cyan box exists for WINDOW[0] <= t < WINDOW[1]
SIZE = (960, 540)  # [px] requested PNG width, height (not the default 1600x900)
MIN_STD = 24.0  # pixel standard deviation: this recording's ~28-32, the empty viewer's ~19.5
MIN_PIXELS = 300  # pixels of each logged colour that must be visible

RED = (255, 0, 0)  # the box at the origin
BLUE = (0, 0, 255)  # the ring of points
CYAN = (0, 255, 255)  # the box that exists only around T
MAGENTA = (255, 0, 255)  # the time series


def _solid_box(center: list[float], half_size: float, colour: tuple[int, int, int]) -> rr.Boxes3D:
    """A filled cube: `center` [m], `half_size` [m]."""
    return rr.Boxes3D(
        centers=[center], half_sizes=[[half_size] * 3], colors=[colour], fill_mode="solid"
    )


def _write_tiny_recording(path: Path) -> None:
    blueprint = rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(origin="/world", name="World"),
            rrb.TimeSeriesView(origin="/metrics", name="Metrics"),
        ),
        collapse_panels=True,
    )
    rec = rr.RecordingStream("avsim_snapshot_test", recording_id=uuid.uuid4())
    rec.save(path, default_blueprint=blueprint)
    rec.log("/world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    rec.log("/metrics/signal", rr.SeriesLines(colors=[MAGENTA], widths=[3.0]), static=True)
    angles = np.linspace(0.0, 2.0 * np.pi, 32, endpoint=False)
    ring = np.stack([4.0 * np.cos(angles), 4.0 * np.sin(angles), np.zeros_like(angles)], axis=1)
    for tick in range(round(END * RATE) + 1):
        t = tick / RATE  # [s]
        rec.set_time("sim_time", duration=t)
        rec.log("/world/box", _solid_box([0.0, 0.0, 1.0], 1.0, RED))
        rec.log("/world/ring", rr.Points3D(ring, colors=[BLUE], radii=0.25))
        if WINDOW[0] <= t < WINDOW[1]:
            rec.log("/world/window", _solid_box([0.0, -2.5, 0.8], 0.8, CYAN))
        elif t >= WINDOW[1]:
            rec.log("/world/window", rr.Clear(recursive=False))
        rec.log("/metrics/signal", rr.Scalars(np.sin(t)))
    rec.disconnect()


@pytest.fixture(scope="module")
def tiny_rrd(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("snapshot") / "tiny.rrd"
    _write_tiny_recording(path)
    return path


def _colour_pixels(rgb: npt.NDArray[np.int16], colour: tuple[int, int, int]) -> int:
    """Pixels whose saturated channels are those of `colour` (any shading), the rest dark."""
    on = np.array(colour) > 0
    lit = (rgb[..., on] > 120).all(axis=-1)
    off = (rgb[..., ~on] < 50).all(axis=-1)
    return int((lit & off).sum())


def _viewer_processes() -> list[psutil.Process]:
    """Rerun viewers below this process (not any child: a `spawn` pool that ran earlier in
    this worker leaves multiprocessing's resource tracker for the process's lifetime)."""
    viewer = str(_rerun_executable())
    return [p for p in psutil.Process().children(recursive=True)
            if p.cmdline()[:1] == [viewer]]


def test_time_range(tiny_rrd: Path) -> None:
    assert recording_time_range(tiny_rrd) == (0.0, END)


def test_snapshot_shows_the_blueprint_at_t(tiny_rrd: Path, tmp_path: Path) -> None:
    out = tmp_path / "shots" / "tiny.png"  # the folder is created
    render_snapshot(tiny_rrd, AT, out, width=SIZE[0], height=SIZE[1])

    with PIL.Image.open(out) as image:
        assert image.size == SIZE
        rgb = np.asarray(image.convert("RGB")).astype(np.int16)
    assert rgb.std() > MIN_STD
    colours = {"red box": RED, "blue points": BLUE, "cyan box": CYAN, "magenta line": MAGENTA}
    seen = {name: _colour_pixels(rgb, colour) for name, colour in colours.items()}
    assert all(count >= MIN_PIXELS for count in seen.values()), seen
    assert [p.name for p in out.parent.iterdir()] == ["tiny.png"]  # no temporary file left
    assert _viewer_processes() == []


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(SnapshotError, match="no such recording"):
        render_snapshot(tmp_path / "nope.rrd", 1.0, tmp_path / "x.png")
    with pytest.raises(SnapshotError, match="no such recording"):
        recording_time_range(tmp_path / "nope.rrd")


def test_not_an_rrd(tmp_path: Path) -> None:
    bad = tmp_path / "bad.rrd"
    bad.write_bytes(b"not a recording\n" * 10)
    with pytest.raises(SnapshotError, match=r"not a readable \.rrd"):
        render_snapshot(bad, 1.0, tmp_path / "x.png")


@pytest.mark.parametrize("at", [-0.1, END + 0.5])
def test_time_out_of_range_names_the_range(tiny_rrd: Path, tmp_path: Path, at: float) -> None:
    out = tmp_path / "x.png"
    out.write_bytes(b"old")
    with pytest.raises(SnapshotError, match=r"outside .* range \[0, 5\] s"):
        render_snapshot(tiny_rrd, at, out)
    assert out.read_bytes() == b"old"  # untouched


def test_no_vulkan_says_what_to_install(
    tiny_rrd: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The Vulkan loader reads its driver list from these (old and new name): no driver found.
    for name in ("VK_ICD_FILENAMES", "VK_DRIVER_FILES"):
        monkeypatch.setenv(name, str(tmp_path / "no_such_icd.json"))
    out = tmp_path / "x.png"
    with pytest.raises(SnapshotError, match="apt-get install mesa-vulkan-drivers"):
        render_snapshot(tiny_rrd, AT, out)
    assert list(tmp_path.iterdir()) == []  # nothing written, not even a temporary file
    assert _viewer_processes() == []
