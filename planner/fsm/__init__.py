"""The state machines: enum + pure transition + the table as data."""
