"""control/ imports only the messages (planner.messages; perception.messages for a whole
stack's interface beside the command) and the shared conventions of world.frames (plus numpy
and the standard library), and is clean under ruff and mypy --strict."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CONTROL = ROOT / "control"
ALLOWED_FIRST_PARTY = {"control", "planner.messages", "perception.messages", "world.frames"}
ALLOWED_THIRD_PARTY = {"numpy"}


def imported_modules(path: Path) -> set[str]:
    modules: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            modules.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module is not None and node.level == 0:
            modules.add(node.module)
    return modules


@pytest.mark.parametrize("path", sorted(CONTROL.glob("*.py")), ids=lambda p: p.name)
def test_control_imports_only_the_plan_and_the_conventions(path: Path) -> None:
    for module in imported_modules(path):
        top = module.split(".")[0]
        if top in sys.stdlib_module_names or top in ALLOWED_THIRD_PARTY:
            continue
        assert top == "control" or module in ALLOWED_FIRST_PARTY, f"{path.name}: {module}"


def _tool(name: str) -> str:
    found = Path(sys.executable).with_name(name)
    if found.exists():
        return str(found)
    which = shutil.which(name)
    if which is None:
        pytest.skip(f"{name} not installed")
    return which


def test_ruff_clean() -> None:
    result = subprocess.run(
        [_tool("ruff"), "check", "control", "tests/control"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr


def test_mypy_strict_clean() -> None:
    result = subprocess.run(
        [_tool("mypy"), "control", "tests/control"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
