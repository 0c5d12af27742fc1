"""Built-in localisers (one module per plugin)."""
