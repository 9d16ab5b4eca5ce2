"""The import rules of ARCHITECTURE.md ("Layout", "The ground-truth boundary"), checked on the
source with `ast` (nothing is imported).

The stack (`perception`, `planner`, `control`) never touches the simulator: no PyBullet, and
from `world` only the static map and the sensor frame types. Stages import only the stage
before them. `world` and `vehicle_urdf` sit below everything else. Each violation is reported
as `file:line: what`.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
OURS = ("vehicle_urdf", "world", "perception", "planner", "control", "avsim", "bench", "tests",
        "examples")
PYBULLET = ("pybullet", "pybullet_utils", "pybullet_data")
STATIC_WORLD = ("world.frames", "world.hdmap")  # the sensor data types and the static map
WORLD_INIT = ("world.core.simd",)  # `world/__init__.py` also pins numpy's dispatch: a leaf
#   of the standard library alone (no numpy, no simulator, no truth), checked below
DYNAMIC_IMPORTS = ("importlib.import_module", "import_module", "__import__")
STACK = ("perception", "planner", "control")  # the stack under test
JUDGE = ("avsim/criteria", "avsim/report")  # the judge: imports nothing of `STACK`
PUBLIC_API = "avsim.stack"  # what a user's stack may import of avsim (and `STATIC_WORLD`)
AGENT = ("avsim/gym",)  # the Gymnasium environment: its agent drives through `PUBLIC_API`


@dataclass(frozen=True)
class Rule:
    """What the files of one package may import: `allowed` modules of ours (a module and
    everything below it), and whether PyBullet is banned."""

    package: str
    allowed: tuple[str, ...]
    no_pybullet: bool


RULES = (
    Rule("perception", ("perception", *STATIC_WORLD), no_pybullet=True),
    Rule("planner", ("planner", "perception.messages", *STATIC_WORLD), no_pybullet=True),
    Rule("control", ("control", "planner.messages", "perception.messages", "world.frames"),
         no_pybullet=True),
    Rule("world", ("world", "vehicle_urdf"), no_pybullet=False),
    Rule("vehicle_urdf", ("vehicle_urdf",), no_pybullet=False),
    Rule("examples", ("examples", PUBLIC_API, *STATIC_WORLD), no_pybullet=True),
)
# avsim enters each stage by its front door: perception's (`perception.perception`, and
# `perception.truth` for privileged truth mode), the
# planner's (`planner.planner`), control's (the `control` package), and the messages; the
# planner's FSM tables are a library the storyboard's state machines share
FRONT_DOORS = ("perception.perception", "perception.truth", "perception.messages",
               "planner.planner", "planner.messages", "planner.fsm.machine", "control.command")


@dataclass(frozen=True)
class Import:
    module: str  # dotted; for `from a import b` each name gives `a.b`
    line: int
    names_follow: bool = False  # the `a` of `from a import b, c`: its names are checked
    from_name: bool = False  # an `a.b` of `from a import b` (`b` may be a module or not)

    @property
    def shown(self) -> str:
        if not self.from_name:
            return self.module
        base, name = self.module.rsplit(".", 1)
        return f"{self.module} (from {base} import {name})"


def module_name(path: Path, root: Path = REPO) -> str:
    """`world/hdmap.py` -> `world.hdmap`; `world/__init__.py` -> `world`."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imports(source: str, module: str, is_package: bool = False) -> Iterator[Import]:
    """Every module a source imports: `import`, `from ... import` (relative ones resolved
    against `module`), and `importlib.import_module("...")` / `__import__("...")` with a
    literal name. Imports under `if TYPE_CHECKING:` count too."""
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            yield from (Import(alias.name, node.lineno) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(node, module, is_package)
            names = [alias.name for alias in node.names if alias.name != "*"]
            yield Import(base, node.lineno, names_follow=len(names) == len(node.names))
            yield from (Import(f"{base}.{name}", node.lineno, from_name=True) for name in names)
        elif isinstance(node, ast.Call) and ast.unparse(node.func) in DYNAMIC_IMPORTS:
            arg = node.args[0] if node.args else None
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                yield Import(arg.value, node.lineno)


def _absolute(node: ast.ImportFrom, module: str, is_package: bool) -> str:
    """The absolute module of a `from` import; `module` is the importing module."""
    if node.level == 0:
        return node.module or ""
    package = module.split(".") if is_package else module.split(".")[:-1]
    base = package[: len(package) - (node.level - 1)]
    return ".".join([*base, *([node.module] if node.module else [])])


def _within(module: str, prefix: str) -> bool:
    return module == prefix or module.startswith(prefix + ".")


def violations(source: str, filename: str, rule: Rule, module: str = "",
               is_package: bool = False) -> list[str]:
    """`filename:line: problem` for each import of `source` that `rule` forbids.

    `from a import b` is checked as `a.b`, so `from world import hdmap` passes and `from
    world import ego` does not (the bare `a` only for PyBullet; `from a import *` as `a`)."""
    found = []
    for imp in imports(source, module or rule.package, is_package):
        top = imp.module.split(".")[0]
        if rule.no_pybullet and top in PYBULLET and not imp.from_name:
            found.append(f"{filename}:{imp.line}: imports {imp.module} (the simulator)")
        elif (top in OURS and not imp.names_follow
              and not any(_within(imp.module, allowed) for allowed in rule.allowed)):
            found.append(f"{filename}:{imp.line}: {rule.package}/ imports {imp.shown}; "
                         f"it may import only {', '.join(rule.allowed)} of ours")
    return sorted(set(found), key=lambda message: (int(message.split(":")[1]), message))


def stack_imports(root: Path = REPO, folders: tuple[str, ...] = JUDGE) -> list[str]:
    """`file:line: imports ...` for each import statement of a stack package (`STACK`) in
    the `.py` files under `root/<folder>/`, wherever it stands in the module (every node of
    its AST: module level, functions, `if TYPE_CHECKING:`, literal dynamic imports), in file
    and line order."""
    found: list[tuple[str, int, str]] = []
    for folder in folders:
        for path in sorted((root / folder).rglob("*.py")):
            source = path.read_text(encoding="utf-8")
            for imp in imports(source, module_name(path, root), path.name == "__init__.py"):
                if imp.module.split(".")[0] in STACK and not imp.from_name:
                    found.append((str(path.relative_to(root)), imp.line, imp.module))
    return [f"{file}:{line}: imports {module}" for file, line, module in sorted(found)]


def package_files(package: str, root: Path = REPO) -> list[Path]:
    return sorted((root / package).rglob("*.py"))


def check_package(rule: Rule, root: Path = REPO) -> list[str]:
    """The violations of `rule` in every `.py` under `root/<package>/`."""
    found = []
    for path in package_files(rule.package, root):
        found += violations(path.read_text(encoding="utf-8"), str(path.relative_to(root)), rule,
                            module_name(path, root), path.name == "__init__.py")
    return found


# ---------------------------------------------------------------------------------------
# The rules on the real source
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("rule", RULES, ids=[rule.package for rule in RULES])
def test_package_imports_follow_the_arrows(rule: Rule) -> None:
    assert package_files(rule.package), f"no .py files under {rule.package}/"
    found = check_package(rule)
    assert not found, "import rule broken:\n" + "\n".join(found)


def test_the_static_world_modules_reach_no_simulator() -> None:
    """The world modules the stack may import (and `world/__init__.py`, which runs first)
    import no PyBullet and no other world module (not even `world.spec`, which holds the
    scenario's truth), so the stack cannot reach the simulator or the truth through them."""
    static = Rule("world (static part)", STATIC_WORLD, no_pybullet=True)
    first = Rule("world (static part)", (*STATIC_WORLD, *WORLD_INIT), no_pybullet=True)
    found = []
    for module in ("world", *STATIC_WORLD, *WORLD_INIT):
        path = REPO / (module.replace(".", "/") + ("/__init__.py" if module == "world" else ".py"))
        assert path.exists(), path
        found += violations(path.read_text(encoding="utf-8"), str(path.relative_to(REPO)),
                            first if module == "world" else static, module,
                            path.name == "__init__.py")
    leaf = (REPO / "world" / "core" / "simd.py").read_text(encoding="utf-8")
    imported = {n.names[0].name.split(".")[0] for n in ast.walk(ast.parse(leaf))
                if isinstance(n, ast.Import)}
    imported |= {n.module.split(".")[0] for n in ast.walk(ast.parse(leaf))
                 if isinstance(n, ast.ImportFrom) and n.module}
    assert imported <= {"__future__", "os", "platform", "sys"}, imported
    assert not found, "the static world modules must stay PyBullet-free:\n" + "\n".join(found)


def test_the_judge_imports_nothing_of_the_stack() -> None:
    """`avsim/criteria/` and `avsim/report/` judge the truth and the run's records with their
    own formulas and types: no import of `perception`, `planner` or `control` anywhere in
    them (in functions and under `if TYPE_CHECKING:` too)."""
    for folder in JUDGE:
        assert list((REPO / folder).rglob("*.py")), f"no .py files under {folder}/"
    found = stack_imports()
    assert not found, "the judge imports the stack:\n" + "\n".join(found)


def test_the_gym_drives_through_the_public_api_only() -> None:
    """`avsim/gym/` (the Gymnasium environment) drives the car as a user's stack does,
    through `avsim.stack`: no import of `perception`, `planner` or `control`."""
    assert list((REPO / AGENT[0]).rglob("*.py")), f"no .py files under {AGENT[0]}/"
    found = stack_imports(folders=AGENT)
    assert not found, "the gym imports the stack:\n" + "\n".join(found)


def test_avsim_enters_each_stage_by_its_front_door() -> None:
    """avsim imports of the stack only the front doors and the messages (`FRONT_DOORS`, or
    the `control` package itself), so that a stage of one's own replaces a whole stage."""
    found = []
    for path in sorted((REPO / "avsim").rglob("*.py")):
        source = path.read_text(encoding="utf-8")
        for imp in imports(source, module_name(path), path.name == "__init__.py"):
            if imp.module.split(".")[0] not in STACK or imp.names_follow:
                continue
            module = imp.module.rsplit(".", 1)[0] if imp.from_name else imp.module
            if module != "control" and not any(_within(module, d) for d in FRONT_DOORS):
                found.append(f"{path.relative_to(REPO)}:{imp.line}: imports {imp.shown}")
    assert not found, "avsim reaches into a stage:\n" + "\n".join(found)


# ---------------------------------------------------------------------------------------
# The checker itself catches violations
# ---------------------------------------------------------------------------------------

PERCEPTION, PLANNER, CONTROL, WORLD, URDF, EXAMPLES = RULES


@pytest.mark.parametrize(
    ("source", "rule", "module", "expected"),
    [
        ("import pybullet\n", PERCEPTION, "perception.lanes", ["x.py:1: imports pybullet"]),
        ("import numpy\nfrom pybullet_utils.bullet_client import BulletClient\n", PLANNER,
         "planner.fsm", ["x.py:2: imports pybullet_utils"]),
        ("import pybullet_data as pd\n", CONTROL, "control.pid", ["x.py:1: imports pybullet_data"]),
        ("import importlib\nm = importlib.import_module('pybullet')\n", PERCEPTION,
         "perception.x", ["x.py:2: imports pybullet"]),
        ("from world.actors import ActorSet\n", PLANNER, "planner.fsm",
         ["x.py:1: planner/ imports world.actors"]),
        ("from world import ego\n", PERCEPTION, "perception.x",
         ["x.py:1: perception/ imports world.ego"]),
        ("import world.truth\n", PERCEPTION, "perception.x",
         ["x.py:1: perception/ imports world.truth"]),
        ("from world import *\n", PERCEPTION, "perception.x",
         ["x.py:1: perception/ imports world;"]),
        ("from planner.messages import Plan\n", PERCEPTION, "perception.x",
         ["x.py:1: perception/ imports planner.messages"]),
        ("from control.pid import Pid\n", PLANNER, "planner.x",
         ["x.py:1: planner/ imports control.pid"]),
        ("from planner.route import lane_path\n", CONTROL, "control.x",
         ["x.py:1: control/ imports planner.route"]),
        ("from world.hdmap import Lane\n", CONTROL, "control.x",
         ["x.py:1: control/ imports world.hdmap"]),
        ("from perception.localization import Ekf\n", PLANNER, "planner.x",
         ["x.py:1: planner/ imports perception.localization"]),
        ("from avsim.runner import Runner\n", WORLD, "world.world",
         ["x.py:1: world/ imports avsim.runner"]),
        ("from world import frames, actors\n", PERCEPTION, "perception.x",
         ["x.py:1: perception/ imports world.actors"]),
        ("if TYPE_CHECKING:\n    from world.ego import EgoTruth\n", PLANNER, "planner.x",
         ["x.py:2: planner/ imports world.ego"]),
        ("import pybullet\nimport pybullet as p\n", CONTROL, "control.x",
         ["x.py:1: imports pybullet", "x.py:2: imports pybullet"]),
        ("from world.spec import RoadSpec\n", URDF, "vehicle_urdf.builder",
         ["x.py:1: vehicle_urdf/ imports world.spec"]),
        ("from world.spec import TrafficLightSpec\n", PLANNER, "planner.junctions",
         ["x.py:1: planner/ imports world.spec"]),
        ("from world import spec\n", PERCEPTION, "perception.lights",
         ["x.py:1: perception/ imports world.spec"]),
    ],
)
def test_checker_reports_file_and_line(source: str, rule: Rule, module: str,
                                       expected: list[str]) -> None:
    found = violations(source, "x.py", rule, module)
    assert len(found) == len(expected), found
    for message, start in zip(found, expected, strict=True):
        assert message.startswith(start), (message, start)


@pytest.mark.parametrize(
    ("source", "rule", "module"),
    [
        ("import numpy as np\nfrom world.frames import GnssFix\n", PERCEPTION, "perception.x"),
        ("from world import hdmap\nfrom world.hdmap import Lane\n", PLANNER, "planner.x"),
        ("from perception.messages import EgoState\n", PLANNER, "planner.x"),
        ("from planner.messages import Plan\nfrom control.pid import Pid\n", CONTROL, "control.x"),
        ("from .pid import Pid\nfrom . import stanley\nfrom ..pid import P\n", CONTROL,
         "control.sub.x"),
        ("import pybullet\nfrom vehicle_urdf import URDF_PATH\n", WORLD, "world.ego.body"),
    ],
)
def test_checker_allows_the_permitted_imports(source: str, rule: Rule, module: str) -> None:
    assert violations(source, "x.py", rule, module) == []


def test_checker_walks_a_package_tree(tmp_path: Path) -> None:
    package = tmp_path / "perception"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "ok.py").write_text("from world.frames import GnssFix\n", encoding="utf-8")
    (package / "sub" / "bad.py").write_text(
        '"""Doc."""\n\nimport numpy as np\nimport pybullet\nfrom ..ok import GnssFix\n'
        "from world.world import World\n",
        encoding="utf-8",
    )
    found = check_package(PERCEPTION, tmp_path)
    bad = str(Path("perception", "sub", "bad.py"))
    assert [message.split(": ")[0] for message in found] == [f"{bad}:4", f"{bad}:6"], found
    assert "pybullet" in found[0] and "world.world" in found[1]


def test_the_judge_check_finds_nested_and_type_checking_imports(tmp_path: Path) -> None:
    report = tmp_path / "avsim" / "report"
    report.mkdir(parents=True)
    (report / "ok.py").write_text("import numpy\nfrom avsim.report.states import LANE_KEEP\n"
                                  "from world.frames import kph\n", encoding="utf-8")
    (report / "bad.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from planner.fsm.machine import StateChange\n"
        "def f() -> None:\n    import perception.tracker\n"
        "import importlib\nm = importlib.import_module('control.pid')\n"
        "from planner import fsm, messages\n"
        "from plannerish import x\n", encoding="utf-8")
    bad = str(Path("avsim", "report", "bad.py"))
    assert stack_imports(tmp_path, ("avsim/report",)) == [
        f"{bad}:3: imports planner.fsm.machine", f"{bad}:5: imports perception.tracker",
        f"{bad}:7: imports control.pid", f"{bad}:8: imports planner"]
