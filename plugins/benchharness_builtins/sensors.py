"""Built-in sensors and pose estimators (filled in as they land)."""
