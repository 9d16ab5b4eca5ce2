"""avsim as a Gymnasium environment (`AvsimEnv`), registered as ``avsim/Scenario-v0``:
``gymnasium.make("avsim/Scenario-v0", scenario="normal_driving")`` once `avsim.gym` is
imported. docs/stack-api.md ("Gymnasium") is the guide."""

from __future__ import annotations

import gymnasium

from avsim.gym.env import AvsimEnv

ENV_ID = "avsim/Scenario-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(ENV_ID, entry_point="avsim.gym.env:AvsimEnv")

__all__ = ["ENV_ID", "AvsimEnv"]
