"""The physics client and clock, rates, rendering, quiet native output."""
