"""NPC vehicles and pedestrians, their behaviours, town traffic."""
