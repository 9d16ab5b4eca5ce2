"""What avsim adds to an OpenSCENARIO file, which carries no pass/fail criteria: a sidecar
file of the YAML format's keys.

The sidecar is `NAME.criteria.yaml` beside `NAME.xosc`, or the file `--criteria` names, or a
bundled set by its name (`--criteria r157`: `sets/r157.criteria.yaml`, UN R157's). It
may set `criteria` (the YAML format's `criteria:` section, the same keys), `seed`,
`sensors`, `duration` (the time limit [s] when the StopTrigger does not fire) and `function`
(`file`: the car under test's automated driving function is on from the start unless a
story activates its controller later; `off`: it starts off whatever the file's Init says,
the driver holding the Init speed with the car's emergency braking on, as the Euro NCAP AEB
tests drive the VUT; a story that activates the controller still switches it on). Left out,
the defaults apply: the criteria that always apply, with route completion off (the
StopTrigger ends the run), seed 0, the default sensors, `MAX_DURATION`.

Overrides (`avsim run --set`, `avsim sweep --set`) take the same keys, plus
`parameters.NAME` for the file's own parameters (`--param NAME=V` is short for it).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from pydantic import Field

from avsim.criteria.registry import CriteriaSettings, setting_keys
from avsim.scenario.convert import sensors_spec, stack_choice
from avsim.scenario.errors import FILE_KEY, LocatedError, ScenarioError
from avsim.scenario.fields import FormatModel, NonNegInt, PosFloat
from avsim.scenario.files import read_raw
from avsim.scenario.model import CriteriaModel, SensorsModel, StackModel
from avsim.scenario.openscenario.references import ReferenceError, Roots
from avsim.scenario.overrides import apply_overrides
from avsim.scenario.validation import validate_as
from avsim.stack.choice import StackChoice
from world.spec import SensorsSpec

MAX_DURATION = 600.0  # [s] a run whose StopTrigger never fires ends here
SUFFIX = ".criteria.yaml"
PARAMETERS = "parameters."  # the override key prefix of the file's own parameters


class SidecarModel(FormatModel):
    """An OpenSCENARIO file's sidecar (module doc)."""

    criteria: CriteriaModel = Field(default_factory=CriteriaModel,
                                    description="The criteria, as in the YAML format.")
    seed: NonNegInt = Field(default=0, description="Random seed, >= 0. Default 0.")
    sensors: SensorsModel = Field(default_factory=SensorsModel,
                                  description="Sensor noise, as in the YAML format.")
    duration: PosFloat = Field(default=MAX_DURATION,
                               description="[s] time limit if the StopTrigger never fires.")
    stack: StackModel = Field(default_factory=StackModel,
                              description="Which stack drives the car, as in the YAML format.")
    function: Literal["file", "off"] = Field(
        default="file", description="The car under test's automated driving function at the "
        "start: `file` (on unless a story activates its controller later) or `off` (the "
        "driver holds the Init speed, emergency braking on). Default `file`.")


@dataclass(frozen=True, slots=True)
class Sidecar:
    """The sidecar's settings, resolved."""

    criteria: CriteriaSettings
    seed: int
    sensors: SensorsSpec
    duration: float  # [s]
    file: Path | None  # the sidecar read, None: the defaults
    function_off: bool = False  # the automated driving function starts off (`function: off`)
    stack: StackChoice = field(default_factory=StackChoice)  # which stack drives the car


SETS = Path(__file__).with_name("sets")  # the bundled criteria sets (`r157`)


def bundled_sets() -> tuple[str, ...]:
    """The names of the bundled criteria sets (`--criteria NAME`)."""
    return tuple(sorted(p.name.removesuffix(SUFFIX) for p in SETS.glob("*" + SUFFIX)))


def sidecar_path(xosc: Path, given: Path | None, roots: Roots | None = None) -> Path | None:
    """The sidecar of `xosc`: `given` (a file, or a bundled set's name: the user's choice,
    allowed anywhere), else `NAME.criteria.yaml` beside it if it exists, which must resolve
    inside `roots` (`references`; None: the folder of `xosc`) and be a regular file."""
    if given is not None:
        named = SETS / f"{given}{SUFFIX}"
        if given.suffix == "" and len(given.parts) == 1 and named.exists():
            return named
        return given
    beside = xosc.with_name(xosc.stem + SUFFIX)
    if not beside.exists():
        return None
    try:
        real = (roots or Roots.of(xosc)).check(beside)
    except ReferenceError as exc:
        raise ScenarioError(str(beside), FILE_KEY, f"the sidecar: {exc}") from None
    if not real.is_file():
        raise ScenarioError(str(beside), FILE_KEY, "the sidecar is not a regular file")
    return beside


def split_overrides(overrides: Mapping[str, object]) -> tuple[dict[str, str],
                                                              dict[str, object]]:
    """(the file's parameters by name, as text; the sidecar's keys)."""
    params = {k.removeprefix(PARAMETERS): _text(v) for k, v in overrides.items()
              if k.startswith(PARAMETERS)}
    rest = {k: v for k, v in overrides.items() if not k.startswith(PARAMETERS)}
    return params, rest


def _text(value: object) -> str:
    """A parameter value as OpenSCENARIO writes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def load_sidecar(path: Path | None, overrides: Mapping[str, object]) -> Sidecar:
    """The sidecar at `path` (None: the defaults) with `overrides` applied; `ScenarioError`
    (one line) for a bad one."""
    shown = str(path) if path is not None else "(overrides)"
    try:
        raw: dict[str, Any] = read_raw(path) if path is not None else {}
        for section in ("criteria", "sensors"):  # overrides may set keys inside them
            raw.setdefault(section, {})
        raw = apply_overrides(raw, overrides)
        model = validate_as(raw, overrides, SidecarModel)
    except LocatedError as problem:
        raise ScenarioError(shown, problem.key, problem.problem) from None
    values: dict[str, object] = {key: getattr(model.criteria, key) for key in setting_keys()}
    if values.get("completes") is None and values.get("reach_s") is None:
        values["completes"] = False  # the StopTrigger ends the run
    return Sidecar(CriteriaSettings.of(values), model.seed, sensors_spec(model.sensors),
                   float(model.duration), path, model.function == "off",
                   stack_choice(model.stack))
