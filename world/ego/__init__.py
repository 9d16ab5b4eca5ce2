"""The ego body: joints, drive, brake, flat tyre, pedal."""
