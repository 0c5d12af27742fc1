"""Robot models: the space manipulator's DH description, URDF and dynamics."""
