"""A PNG of a recording's default blueprint at one simulated time, drawn by Rerun's own viewer.

`render_snapshot(run.rrd, at=T, out=png)`:

1. reads the recording's `sim_time` range with `rerun.chunk.RrdReader`, which also tells a
   missing or broken file, and checks that T lies in it;
2. starts a headless Rerun viewer (`rerun --headless`, the binary of the installed rerun-sdk)
   on a free local port, with a fixed window size and `WGPU_BACKEND=vulkan`: without a GPU it
   renders on the CPU through Mesa's lavapipe (Debian package `mesa-vulkan-drivers`);
3. drives it with `rerun.experimental.ViewerClient`: `open` the file, wait until the viewer's
   `loading` list is empty, then `set_time` (paused at T on `sim_time`);
4. takes screenshots until `STABLE_SHOTS` consecutive ones, taken at least `TOAST_TIME`
   after launch, are byte-identical. The viewer loads a local `.rrd` through its catalog and
   fetches the chunks around the time cursor on demand after `open` returns, and the 3D
   views' eyes settle over the first frames, so the first screenshot is often incomplete; a
   frame with a chunk still in flight shows an animated loading indicator, so it never repeats
   exactly. The start-up toast, though, goes by wall-clock time, hence the minimum age;
5. writes the PNG atomically (a temporary file beside `out`, then a rename), and always ends
   the viewer's process group.

The one-shot `rerun --screenshot-to` fires before the data has loaded, hence the client.
"""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from importlib.util import find_spec
from pathlib import Path
from typing import IO

import numpy as np
from rerun.chunk import RrdReader
from rerun.experimental import ViewerClient

from avsim.files import write_atomic
from avsim.record.blueprint import TIMELINE

NS_PER_S = 1_000_000_000  # [ns/s]
POLL_PERIOD = 0.1  # [s] between two polls of the viewer while it starts or loads
STABLE_SHOTS = 3  # [-] consecutive identical screenshots that count as "everything drawn"
# [s] after launch before a screenshot may count as settled: the viewer's start-up toast
# ("Listening for gRPC connections ...") stays for a while of wall-clock time, during which
# consecutive frames are identical; this is beyond it.
TOAST_TIME = 3.0
QUIT_TIMEOUT = 5.0  # [s] the viewer gets to exit after SIGTERM, before SIGKILL
HOST = "127.0.0.1"  # the viewer listens on loopback only
# the panels a fresh viewer opens with (sources and blueprint, selection, time), closed so
# that the blueprint's views get the whole picture
PANEL_TOGGLES = ("ui.toggle_blueprint_panel", "ui.toggle_selection_panel",
                 "recording.toggle_time_panel")
INSTALL_HINT = "apt-get install mesa-vulkan-drivers"  # CPU Vulkan (lavapipe) on Debian
# The child's environment on top of the caller's: Vulkan (lavapipe on a GPU-less machine); no
# first-run analytics prompt; only errors in the log, which also keeps the warning toasts
# (software rasterizer) out of the picture.
VIEWER_ENV = {"WGPU_BACKEND": "vulkan", "RERUN_APP_ONLY": "true", "RUST_LOG": "error"}
NO_ADAPTER_MARKERS = ("No graphics adapter", "Failed to create render state")  # viewer panics


class SnapshotError(Exception):
    """A snapshot could not be made; the message is one line that says why. `key` names
    what was at fault, as the CLI reports it (``<file>: <key>: <message>``): the file,
    ``--at``, or the viewer."""

    def __init__(self, problem: str, key: str = "(viewer)") -> None:
        super().__init__(problem)
        self.key = key


def recording_time_range(recording: Path) -> tuple[float, float]:
    """The first and last `sim_time` of the first recording in an `.rrd` file, [s].

    Reads every chunk on the `sim_time` timeline (`RrdReader(...).stream()`). Raises
    `SnapshotError` if the file is missing, is not a readable `.rrd`, or holds no `sim_time`
    data.
    """
    start_ns, end_ns = _time_range_ns(recording)
    return start_ns / NS_PER_S, end_ns / NS_PER_S


def render_snapshot(
    recording: Path,
    at: float,
    out: Path,
    *,
    width: int = 1600,
    height: int = 900,
    timeout: float = 60.0,
) -> None:
    """Render `recording`'s default blueprint at `sim_time` = `at` [s] to the PNG `out`.

    The PNG is `width` x `height` [px] (the viewer's window, at one pixel per point).
    `timeout` [s] bounds the whole run: viewer start, load and settling; a single viewer call
    may block up to 15 s more (the client's own limit). Creates `out`'s folder if needed; an
    existing `out` is replaced only by a complete PNG. Raises `SnapshotError` for a missing or
    broken file, `at` outside the recording's `sim_time` range, a viewer that cannot start (no
    Vulkan) or does not settle in time. The viewer process is ended in every case.
    """
    start_ns, end_ns = _time_range_ns(recording)
    at_ns = round(at * NS_PER_S) if math.isfinite(at) else end_ns + 1
    if not start_ns <= at_ns <= end_ns:
        raise SnapshotError(
            f"T = {at:g} s is outside the recording's {TIMELINE} range "
            f"[{start_ns / NS_PER_S:g}, {end_ns / NS_PER_S:g}] s", key="--at"
        )
    deadline = time.monotonic() + timeout
    with _headless_viewer(width, height) as viewer:
        try:
            png = _capture(viewer, recording.resolve(), at_ns, deadline)
        except SnapshotError:
            raise
        except Exception as err:  # the client's errors: transport, timeouts, viewer replies
            raise viewer.failure(err) from err
    _check_size(png, width, height)
    write_atomic(out, png)


# -- the recording ---------------------------------------------------------------------------


def _time_range_ns(recording: Path) -> tuple[int, int]:
    """First and last `sim_time` [ns] of the file's first recording."""
    if not recording.is_file():
        raise SnapshotError("no such recording file", key="(file)")
    starts: list[int] = []
    ends: list[int] = []
    try:
        for chunk in RrdReader(recording).stream().filter(has_timeline=TIMELINE):
            batch = chunk.to_record_batch()
            column = batch.column(batch.schema.get_field_index(TIMELINE))
            times = np.asarray(column.to_numpy(zero_copy_only=False), dtype="timedelta64[ns]")
            times = times[~np.isnat(times)].view(np.int64)
            if times.size:
                starts.append(int(times.min()))
                ends.append(int(times.max()))
    except (ValueError, RuntimeError, OSError) as err:
        raise SnapshotError(f"not a readable .rrd: {_first_line(err)}", key="(file)") from err
    if not starts:
        raise SnapshotError(f"no {TIMELINE} data in the recording", key="(file)")
    return min(starts), max(ends)


# -- the viewer ------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Viewer:
    """A running headless viewer: its process (own process group) and its stderr log."""

    process: subprocess.Popen[bytes]
    url: str  # rerun+http://127.0.0.1:<port>/proxy
    log: IO[bytes]  # the child's stderr, a temporary file
    launched: float  # [s] time.monotonic() at launch

    def failure(self, err: BaseException | None = None) -> SnapshotError:
        """A one-line error for a viewer that failed; names the package if Vulkan is missing."""
        self.log.seek(0)
        text = self.log.read().decode(errors="replace")
        if any(marker in text for marker in NO_ADAPTER_MARKERS):
            return SnapshotError(
                f"the headless Rerun viewer found no Vulkan adapter: {INSTALL_HINT}"
            )
        code = self.process.poll()
        if code is not None:
            panic = [line for line in text.splitlines() if "panicked" in line]
            return SnapshotError(f"the Rerun viewer exited with code {code}: {_last(panic)}")
        return SnapshotError(f"the Rerun viewer failed: {_first_line(err)}")


@contextmanager
def _headless_viewer(width: int, height: int) -> Iterator[_Viewer]:
    """Start `rerun --headless` with a `width` x `height` [pt] window; end its process group
    on exit."""
    port = _free_port()
    command = [
        str(_rerun_executable()),
        "--headless",
        "--hide-welcome-screen",
        f"--bind={HOST}",
        f"--port={port}",
        f"--window-size={width}x{height}",
    ]
    with tempfile.TemporaryFile() as log:
        launched = time.monotonic()
        process = subprocess.Popen(
            command,
            env={**os.environ, **VIEWER_ENV},
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=log,
            start_new_session=True,  # its own process group, so one killpg ends it all
        )
        try:
            yield _Viewer(process, f"rerun+http://{HOST}:{port}/proxy", log, launched)
        finally:
            _end_process_group(process)


def _rerun_executable() -> Path:
    """The native `rerun` binary shipped in the `rerun_cli` package of rerun-sdk."""
    spec = find_spec("rerun_cli")
    if spec is None or spec.origin is None:
        raise SnapshotError("the Rerun viewer is missing: pip install rerun-sdk")
    executable = Path(spec.origin).parent / "rerun"
    if not executable.is_file():
        raise SnapshotError(f"the Rerun viewer binary is missing: {executable}")
    return executable


def _free_port() -> int:
    """A TCP port on loopback that is free right now (the OS picks it)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind((HOST, 0))
        port: int = probe.getsockname()[1]
    return port


def _end_process_group(process: subprocess.Popen[bytes]) -> None:
    """SIGTERM the viewer's process group, SIGKILL it after `QUIT_TIMEOUT`, and reap it."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        with suppress(ProcessLookupError):  # the whole group has exited already
            os.killpg(process.pid, sig)
        try:
            process.wait(QUIT_TIMEOUT)
            return
        except subprocess.TimeoutExpired:
            continue


# -- driving it ------------------------------------------------------------------------------


def _capture(viewer: _Viewer, recording: Path, at_ns: int, deadline: float) -> bytes:
    """Open `recording`, seek to `at_ns` [ns], and return a settled screenshot (PNG bytes)."""
    client = _connect(viewer, deadline)
    opened = client.open(str(recording))
    store_ids = [store for store in opened.store_ids if store.startswith("Recording:")]
    if not store_ids:
        raise SnapshotError(f"the Rerun viewer opened no recording from {recording}")
    while client.get_state().loading:
        _wait_or_fail(viewer, deadline, "to load the recording")
    for command in PANEL_TOGGLES:
        store = store_ids[0] if command.startswith("recording.") else None
        client.run_command(command, store_id=store)
    client.set_time(
        TIMELINE,
        duration=np.timedelta64(at_ns, "ns"),
        play_state="paused",
        recording=store_ids[0],
    )
    return _settled_screenshot(viewer, client, deadline)


def _connect(viewer: _Viewer, deadline: float) -> ViewerClient:
    """A client for `viewer`, once it answers (it listens shortly after launch)."""
    while True:
        try:
            client = ViewerClient.connect(viewer.url)
            client.get_state()
            return client
        except ConnectionError:
            _wait_or_fail(viewer, deadline, "to start")


def _settled_screenshot(viewer: _Viewer, client: ViewerClient, deadline: float) -> bytes:
    """Screenshots until `STABLE_SHOTS` in a row, all `TOAST_TIME` after launch, are identical.

    Each screenshot also makes the headless viewer draw a frame, which is what moves loading
    and camera animations on; so keep taking them, with no sleep between.
    """
    last = b""
    repeats = 0  # identical screenshots in a row, counted from TOAST_TIME on
    while repeats < STABLE_SHOTS:
        _check_alive(viewer, deadline, "to settle")
        toast_gone = time.monotonic() - viewer.launched >= TOAST_TIME
        shot = client.take_screenshot()
        same = shot == last and repeats > 0
        repeats = (repeats + 1 if same else 1) if toast_gone else 0
        last = shot
    return last


def _wait_or_fail(viewer: _Viewer, deadline: float, what: str) -> None:
    """Sleep one `POLL_PERIOD`, unless the viewer died or the deadline passed."""
    _check_alive(viewer, deadline, what)
    time.sleep(POLL_PERIOD)


def _check_alive(viewer: _Viewer, deadline: float, what: str) -> None:
    """`SnapshotError` if the viewer has exited or the deadline passed (waiting for `what`)."""
    if viewer.process.poll() is not None:
        raise viewer.failure()
    if time.monotonic() > deadline:
        raise SnapshotError(f"timed out waiting for the Rerun viewer {what}")


# -- the PNG ---------------------------------------------------------------------------------


def _check_size(png: bytes, width: int, height: int) -> None:
    """The PNG's IHDR size must be the requested one [px]."""
    if png[:8] != b"\x89PNG\r\n\x1a\n" or len(png) < 24:
        raise SnapshotError("the Rerun viewer returned no PNG")
    got = (int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big"))
    if got != (width, height):
        raise SnapshotError(f"the screenshot is {got[0]}x{got[1]} px, not {width}x{height} px")


def _first_line(err: BaseException | None) -> str:
    """The first line of `err`'s message, else its type's name."""
    lines = str(err).strip().splitlines() if err is not None else []
    return lines[0] if lines else type(err).__name__


def _last(lines: list[str]) -> str:
    """The last of `lines`, stripped, or a placeholder for none."""
    return lines[-1].strip() if lines else "no panic message"
