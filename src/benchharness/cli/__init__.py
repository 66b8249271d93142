"""The ``benchharness`` command line: thin wrappers that parse, call, print."""
