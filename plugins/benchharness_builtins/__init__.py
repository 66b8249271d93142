"""Built-in plugins of benchharness.

Each module here is named by an entry point in the ``benchharness`` group of
this distribution's ``pyproject.toml`` and is loaded exactly like a
third-party plugin: there is no other registry.
"""
