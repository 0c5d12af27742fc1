"""Built-in path planners (one module per plugin)."""
