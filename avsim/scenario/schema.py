"""The JSON Schema of the scenario format `avsim/1`, generated from the pydantic models.

`avsim schema` prints it. It describes the whole public format, including the keys the
simulator does not simulate yet (`avsim.scenario.load.UNSUPPORTED`); checks that span several
keys (a lane exists at a station, `after` names an earlier action, ...) are made by
`avsim.scenario.checks` when a file is loaded, not by the schema.
"""

from __future__ import annotations

from typing import Any

from avsim.scenario.model import FORMAT, ScenarioModel

SCHEMA_DIALECT = "https://json-schema.org/draft/2020-12/schema"
SCHEMA_ID = "urn:avsim:scenario-format:avsim-1"


def scenario_json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a scenario file, as a JSON-ready dict."""
    body = ScenarioModel.model_json_schema(mode="validation")
    body.pop("title", None)
    return {
        "$schema": SCHEMA_DIALECT,
        "$id": SCHEMA_ID,
        "title": f"avsim scenario file (format {FORMAT})",
        **body,
        "description": (
            "A scenario for the avsim driving sandbox. Units: metres, seconds; keys ending in "
            "_kph are km/h, _deg degrees. Stations `s` are metres along the ego's route from "
            "its start; lateral offsets are metres, left positive. See docs/scenario-format.md."
        ),
    }
