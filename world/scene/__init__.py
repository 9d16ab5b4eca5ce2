"""Bodies and meshes: road surface and paint, scenery, bumps, signs, lights."""
