"""Built-in backends (filled in as the feature lands)."""
