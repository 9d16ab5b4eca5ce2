"""Criteria: one module per family, and the registry that builds a scenario's set."""
