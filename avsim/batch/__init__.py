"""Batches of runs: jobs, executors (local processes, Ray), suite, sweep."""
