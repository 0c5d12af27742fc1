"""Independent yardsticks plugins are measured with: a trajectory's swept clearance from
the true shapes, and the fuel cost of flying a task plan."""
