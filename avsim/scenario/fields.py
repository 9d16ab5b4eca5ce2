"""The scenario format's building blocks, shared by its models (`avsim.scenario.model`) and
by the criteria's settings (`avsim.criteria`, whose declarations give the `criteria:`
section its keys): the strict base model, the constrained scalars, and the error that
carries a ready-made message.

Strict: an unknown key is an error, text is never coerced into a number (an integer is
accepted where a float is expected), NaN and infinities are refused, a model is immutable.
Units are the file's (`*_kph` km/h, `*_deg` degrees, everything else SI).
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field
from pydantic_core import PydanticCustomError

# Constrained scalars. Strict mode (model config) refuses text for numbers and floats for
# ints; a float field accepts an int.
PosFloat = Annotated[float, Field(gt=0)]
NonNegFloat = Annotated[float, Field(ge=0)]
NonNegInt = Annotated[int, Field(ge=0)]
PosInt = Annotated[int, Field(ge=1)]
Fraction = Annotated[float, Field(ge=0, le=1)]


class FormatModel(BaseModel):
    """Base of every scenario model: strict, no unknown keys, no NaN/inf, immutable."""

    model_config = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False, frozen=True)


def problem(message: str, key: str | None = None) -> PydanticCustomError:
    """A validation error with a ready-made message; `key` (if given) is the offending key
    below the location of the model that raises it. `avsim.scenario.validation` formats it
    into the one-line `<file>: <key.path>: <problem>`."""
    context: dict[str, Any] = {"problem": message}
    if key is not None:
        context["key"] = key
    return PydanticCustomError("avsim", "{problem}", context)
