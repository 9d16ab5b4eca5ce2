"""Which stack drives the car: the bundled one, a user's whole stack, or the bundled one with
some stages replaced (`StackChoice`), and how a choice is found and built.

A choice names factories: ``"package.module:factory"`` (a callable taking a
`avsim.stack.StackContext`; the module imported as Python finds it, the current folder
first), ``"path/to/file.py:factory"`` (the file loaded as a module of its own), or the name
of an entry point of the group ``avsim.stacks``
(an installed package's ``[project.entry-points."avsim.stacks"] my-stack =
"my_stack:make"``), or ``"avsim"``, the bundled stack (for `stack`) or stage. A whole stack's
factory returns a `control.command.DrivingStack`; a stage's factory returns a
`perception.messages.PerceptionStage`, `planner.messages.PlannerStage` or
`control.command.ControllerStage`. `resolve` imports a factory (a `StackChoiceError`, one
line, if it cannot); `build` calls them.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.metadata
import importlib.util
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

BUNDLED = "avsim"  # the bundled stack, or a bundled stage
GROUP = "avsim.stacks"  # the entry-point group of installed stacks
STAGES = ("perception", "planner", "controller")
TRUTH_PERCEPTION = "avsim.stack.bundled:truth_perception"  # the bundled perception stage of
#   privileged truth mode: it reads the `truth` sensor only
SPEC = re.compile(r"^(?:(?:[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*|[\w./-]+\.py)"
                  r":[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*"
                  r"|[A-Za-z0-9][\w.-]*)$")  # module:attribute, file.py:attribute, or an
#   entry point's name
MAX_SPEC = 200  # [characters] of one factory's name
Factory = Callable[..., object]


class StackChoiceError(Exception):
    """A stack or stage that cannot be found: `key` names the choice (`stack`,
    `perception`, ...), `problem` says why, in one line."""

    def __init__(self, key: str, problem: str) -> None:
        super().__init__(key, problem)
        self.key = key
        self.problem = problem

    def __str__(self) -> str:
        return f"{self.key}: {self.problem}"


@dataclass(frozen=True, slots=True)
class StackChoice:
    """The factories of the stack (module doc); None: the bundled one. A whole `stack`
    other than the bundled one replaces every stage: it cannot be given with a stage."""

    stack: str | None = None
    perception: str | None = None
    planner: str | None = None
    controller: str | None = None
    privileged: bool = False  # privileged truth mode: the car also has the `truth` sensor
    #   (the ground truth, `world.frames.GroundTruth`), and every result says so

    def __post_init__(self) -> None:
        for key in ("stack", *STAGES):
            value = getattr(self, key)
            if value is not None and (len(value) > MAX_SPEC or not SPEC.match(value)):
                raise StackChoiceError(key, f"{value[:MAX_SPEC]!r} is not a factory: "
                                       "give package.module:factory or an installed stack's "
                                       f"name (entry point group {GROUP})")
        if self.whole and any(getattr(self, s) not in (None, BUNDLED) for s in STAGES):
            raise StackChoiceError("stack", "a whole stack replaces every stage: give "
                                   "either a stack or stages to replace, not both")

    @property
    def whole(self) -> bool:
        """A user's whole stack drives the car."""
        return self.stack not in (None, BUNDLED)

    @property
    def own_perception(self) -> bool:
        """A user's code perceives and localises: a whole stack, or a perception stage
        other than the bundled one."""
        return self.whole or self.perception not in (None, BUNDLED)

    @property
    def bundled(self) -> bool:
        """Every stage is the bundled one."""
        return not self.whole and all(getattr(self, s) in (None, BUNDLED) for s in STAGES)

    def label(self) -> str:
        """One line naming the choice: "avsim", a whole stack's factory, or the stages."""
        if self.whole:
            return str(self.stack)
        if self.bundled:
            return BUNDLED
        return ", ".join(f"{s} {getattr(self, s)}" for s in STAGES
                         if getattr(self, s) not in (None, BUNDLED))

    def as_json(self) -> dict[str, str]:
        """The factories of the stack and of each stage ("avsim": bundled)."""
        return {key: getattr(self, key) or BUNDLED for key in ("stack", *STAGES)}


def resolve(key: str, spec: str) -> Factory:
    """The factory `spec` names (module doc); `key` names the choice in an error."""
    if ":" in spec:
        module_name, _, attribute = spec.partition(":")
        target: object = _module(key, spec, module_name)
        for part in attribute.split("."):
            if not hasattr(target, part):
                raise StackChoiceError(key, f"{spec}: {module_name} has no {attribute}")
            target = getattr(target, part)
    else:
        found = [e for e in importlib.metadata.entry_points(group=GROUP) if e.name == spec]
        if not found:
            known = sorted(e.name for e in importlib.metadata.entry_points(group=GROUP))
            raise StackChoiceError(key, f"no installed stack {spec!r} (entry point group "
                                   f"{GROUP}: {', '.join(known) or 'none installed'}); a "
                                   "factory is package.module:factory")
        try:
            target = found[0].load()
        except Exception as exc:
            raise StackChoiceError(key, f"{spec}: cannot load its entry point "
                                   f"{found[0].value}: {type(exc).__name__}: {exc}") from None
    if not callable(target):
        raise StackChoiceError(key, f"{spec} is not callable (a factory takes a "
                               "StackContext)")
    return target


def _module(key: str, spec: str, name: str) -> object:
    """The module `name` of the factory `spec`: a file ``*.py`` loaded as a module named
    after its path, else imported with the current folder first on the path."""
    try:
        if name.endswith(".py"):
            path = Path(name).resolve()
            if not path.is_file():
                raise StackChoiceError(key, f"{spec}: no file {name}")
            module_name = "avsim_user_stack_" + re.sub(r"\W", "_", str(path))
            if module_name in sys.modules:
                return sys.modules[module_name]
            found = importlib.util.spec_from_file_location(module_name, path)
            assert found is not None and found.loader is not None
            module = importlib.util.module_from_spec(found)
            sys.modules[module_name] = module
            try:
                found.loader.exec_module(module)
            except BaseException:
                del sys.modules[module_name]
                raise
            return module
        here = str(Path.cwd())
        if here not in sys.path:
            sys.path.insert(0, here)
        return importlib.import_module(name)
    except StackChoiceError:
        raise
    except Exception as exc:  # a user's module may raise anything on import
        raise StackChoiceError(key, f"{spec}: cannot import {name}: "
                               f"{type(exc).__name__}: {exc}") from None


def version_of(spec: str) -> str:
    """The version of the factory `spec`: its module's ``__version__``, else its top-level
    package's, else that of the installed distribution that provides the package; "unknown"
    if none says."""
    if ":" in spec:
        module_name = spec.partition(":")[0]
    else:
        found = [e for e in importlib.metadata.entry_points(group=GROUP) if e.name == spec]
        if not found:
            return "unknown"
        module_name = found[0].value.partition(":")[0].strip()
    if module_name.endswith(".py"):
        try:
            own = _module("stack", spec, module_name)
        except StackChoiceError:
            return "unknown"
        version = getattr(own, "__version__", None)
        return version if isinstance(version, str) else "unknown"
    top = module_name.split(".")[0]
    for name in dict.fromkeys((module_name, top)):
        try:
            module = importlib.import_module(name)
        except Exception:  # a user's module may raise anything on import
            continue
        if isinstance(getattr(module, "__version__", None), str):
            return str(module.__version__)
    for dist in importlib.metadata.packages_distributions().get(top, []):
        try:
            return importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            continue
    return "unknown"


@dataclass(frozen=True, slots=True)
class StackIdentity:
    """Which stack drove a run, as its result, JUnit and summary name it."""

    name: str  # `StackChoice.label`
    version: str  # the whole stack's version, avsim's for the bundled one, else the
    #   replaced stages' ("perception 1.2, planner 0.3")
    api: str  # the stack API's version (`avsim.stack.API_VERSION`)
    factories: dict[str, str]  # stack and each stage -> its factory ("avsim": bundled)
    privileged: bool = False  # privileged truth mode: the stack was given the ground truth

    def as_json(self) -> dict[str, object]:
        return {"name": self.name, "version": self.version, "api": self.api,
                "factories": dict(self.factories), "privileged": self.privileged}


def code_digest(choice: StackChoice) -> str:
    """SHA-256 over the source files of the modules of the choice's own factories ("" for
    the bundled stack, whose code avsim's fingerprint covers): a campaign resumes a run only
    on the same code (`avsim.batch.resume`)."""
    digest = hashlib.sha256()
    own = [str(getattr(choice, k)) for k in ("stack", *STAGES)
           if getattr(choice, k) not in (None, BUNDLED)]
    for spec in own:
        target = resolve("stack", spec)
        module = sys.modules.get(getattr(target, "__module__", "") or "")
        source = getattr(module, "__file__", None)
        digest.update(spec.encode() + b"\0")
        if source is not None and Path(source).is_file():
            digest.update(hashlib.sha256(Path(source).read_bytes()).digest())
    return digest.hexdigest() if own else ""


def identity(choice: StackChoice, api: str) -> StackIdentity:
    """The identity of `choice` (its factories' versions looked up now)."""
    own = importlib.metadata.version("avsim")
    if choice.whole:
        version = version_of(str(choice.stack))
    elif choice.bundled:
        version = own
    else:
        version = ", ".join(f"{s} {version_of(str(getattr(choice, s)))}" for s in STAGES
                            if getattr(choice, s) not in (None, BUNDLED))
    return StackIdentity(choice.label(), version, api, choice.as_json(), choice.privileged)
