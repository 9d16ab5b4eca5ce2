"""The avsim/1 scenario format: load, model, checks, convert, JSON Schema."""
