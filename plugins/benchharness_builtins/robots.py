"""Built-in robots (filled in as the feature lands)."""
