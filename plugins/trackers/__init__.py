"""Built-in trackers (one module per plugin)."""
