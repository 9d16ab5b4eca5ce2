"""Runs `avsim` invocations one after another in this one process (click's runner), each in
its own working directory, and prints each one's outcome as JSON: what the command-line tests
judge of a bad input that is not the process boundary, at one interpreter start for all.

Input (stdin): a JSON list of [name, [args...], cwd]. Output (stdout): a JSON object, name ->
{"returncode", "stdout", "stderr", "pybullet"}; "pybullet" is true when PyBullet is imported
after the invocation (by it or by one before it: none of the cases may import it, so the
first that does is flagged, and every one after it, never hidden): a bad input must be
refused before the simulator is imported, which a real process shows as PyBullet's banner.
"""

from __future__ import annotations

import json
import os
import sys

from click.testing import CliRunner

from avsim.cli import main


def run_all(cases: list[tuple[str, list[str], str]]) -> dict[str, dict[str, object]]:
    """Each case's outcome (module doc)."""
    outcomes: dict[str, dict[str, object]] = {}
    for name, args, cwd in cases:
        os.chdir(cwd)
        result = CliRunner().invoke(main, args)
        crashed = result.exception is not None and not isinstance(result.exception,
                                                                  SystemExit)
        outcomes[name] = {
            "returncode": result.exit_code,
            "stdout": result.stdout,
            "stderr": result.stderr + (f"Traceback: {result.exception!r}" if crashed else ""),
            "pybullet": "pybullet" in sys.modules,
        }
    return outcomes


if __name__ == "__main__":
    json.dump(run_all(json.load(sys.stdin)), sys.stdout)
