"""numpy's dispatch is held at x86-64-v3 wherever avsim runs, so that a scenario gives the
same trajectory on a CPU with AVX-512 as on one without (its transcendental kernels round
differently in the last bit)."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from pathlib import Path

import pytest

from world.core.simd import AVX512_GROUPS, NUMPY_ENV, X86_64

REPO = Path(__file__).resolve().parents[3]
pytestmark = pytest.mark.skipif(platform.machine().lower() not in X86_64, reason="x86-64 only")

PROBE = ("import numpy._core._multiarray_umath as m; print(sorted("
         "k for k, v in m.__cpu_features__.items() if v and k in m.__cpu_dispatch__))")


def dispatched(first_import: str, env: dict[str, str]) -> str:
    """The dispatch targets numpy uses in a fresh process that imports `first_import` first."""
    code = f"import {first_import}; {PROBE}"
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=REPO, check=True,
                         capture_output=True, text=True)
    return out.stdout


@pytest.mark.parametrize("first_import", [
    "avsim.cli", "world.frames", "bench", "control", "control.longitudinal", "planner",
    "planner.acc_layer", "perception", "perception.lanes"])
def test_no_avx512_kernel_whichever_package_comes_first(first_import: str) -> None:
    env = {k: v for k, v in os.environ.items() if k != NUMPY_ENV}
    env["PYTHONPATH"] = str(REPO)
    used = dispatched(first_import, env)
    for group in AVX512_GROUPS.split():
        assert f"'{group}'" not in used


def test_this_test_process_is_pinned_too() -> None:
    assert os.environ.get(NUMPY_ENV) == AVX512_GROUPS or NUMPY_ENV in os.environ
    import numpy._core._multiarray_umath as m

    assert not any(m.__cpu_features__.get(g) and g in m.__cpu_dispatch__
                   for g in AVX512_GROUPS.split())


def test_a_users_own_setting_is_kept() -> None:
    env = {**os.environ, NUMPY_ENV: "AVX512_SPR", "PYTHONPATH": str(REPO)}
    code = "import avsim, os; print(os.environ['NPY_DISABLE_CPU_FEATURES'])"
    out = subprocess.run([sys.executable, "-c", code], env=env, check=True,
                         capture_output=True, text=True)
    assert out.stdout.strip() == "AVX512_SPR"
