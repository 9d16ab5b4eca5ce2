"""Scenario file texts shared by the loading and the CLI tests."""

MINIMAL = """\
format: avsim/1
name: minimal
duration: 10
road:
  speed_limit_kph: 50
  segments:
    - straight: 100
ego: {s: 10, set_speed_kph: 40}
"""
