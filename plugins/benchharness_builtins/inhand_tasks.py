"""Built-in inhand_tasks (filled in as the feature lands)."""
