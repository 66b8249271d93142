"""Built-in rubiks_tasks (filled in as the feature lands)."""
