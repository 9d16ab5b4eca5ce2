"""The avsim/1 scenario format and the scenario a run takes: load (files, overrides,
validation, errors), model (with its building blocks, fields), checks, convert, the
Scenario type, JSON Schema."""
