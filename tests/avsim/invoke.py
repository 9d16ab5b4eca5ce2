"""`avsim ARGS` in this process (click's runner), in a working directory, as a finished
process: for the tests that judge a command's exit status, output and files, not the
process boundary (an interpreter start and avsim's imports cost ~1.6 s a subprocess)."""

from __future__ import annotations

import contextlib
import subprocess
from pathlib import Path

from click.testing import CliRunner

from avsim.cli import main


def invoke(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """`avsim ARGS` run in `cwd`: its exit status, stdout and stderr. An exception that is
    not an exit (what a real process shows as a traceback and exit 1) is raised here."""
    with contextlib.chdir(cwd):
        result = CliRunner().invoke(main, list(args))
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise result.exception
    return subprocess.CompletedProcess(["avsim", *args], result.exit_code, result.stdout,
                                       result.stderr)
