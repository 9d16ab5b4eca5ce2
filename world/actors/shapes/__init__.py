"""Bodies' shapes as data: every vehicle of the catalogue and Euro NCAP's test targets, each a
tuple of convex parts with a material, and the Wavefront OBJ files made from them.

A leaf package (numpy and scipy only, no PyBullet): a body is described here, the world turns
the description into Bullet shapes and visuals.

The body frame (every shape, every file): x forward, y left, z up, in metres; the origin is
the centre of the body's bounding-box footprint at ground level, so the ground is z = 0, the
box spans x in [-length/2, length/2], y in [-width/2, width/2], z in [0, height], and the
wheels stand on z = 0. (A Bullet body placed at its box centre is this frame raised by
height/2.) A pedestrian's origin is the centre of the target's published envelope, which its
moving legs stay inside.
"""
