"""Built-in controllers (one module per plugin)."""
