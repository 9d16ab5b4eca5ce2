"""The Rerun recording: recorder, blueprint, headless snapshots."""
