"""The car's sensors: cameras, LiDAR (+ culling), GNSS / odometry, the rig, the pipelines."""
