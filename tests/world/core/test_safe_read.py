"""`read_bounded`: only regular files, never past the bound, nothing that blocks."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from world.core.safe_read import UnreadableFileError, read_bounded


def test_reads_a_regular_file_whole(tmp_path: Path) -> None:
    f = tmp_path / "a.yaml"
    f.write_bytes(b"x" * 100)
    assert read_bounded(f, 100) == b"x" * 100


def test_a_file_over_the_bound_is_refused(tmp_path: Path) -> None:
    f = tmp_path / "a.yaml"
    f.write_bytes(b"x" * 101)
    with pytest.raises(UnreadableFileError, match="over 100 bytes"):
        read_bounded(f, 100)


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/null"])
def test_a_device_is_refused_also_through_a_symlink(tmp_path: Path, device: str) -> None:
    link = tmp_path / "s.yaml"
    link.symlink_to(device)
    for path in (Path(device), link):
        with pytest.raises(UnreadableFileError, match="character device"):
            read_bounded(path, 1000)


def test_a_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "f.yaml"
    os.mkfifo(fifo)
    with pytest.raises(UnreadableFileError, match="FIFO"):
        read_bounded(fifo, 1000)


def test_missing_directory_and_loop(tmp_path: Path) -> None:
    loop = tmp_path / "loop.xodr"
    loop.symlink_to(loop)
    cases = {tmp_path / "none.yaml": "no such file", tmp_path: "directory", loop: "symlink loop"}
    for path, words in cases.items():
        with pytest.raises(UnreadableFileError, match=words):
            read_bounded(path, 1000)
