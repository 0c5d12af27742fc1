"""Built-in task planners (one module per plugin)."""
