"""One run: the runner loop, the stack's wiring, the sensor loop, scoring, results."""
