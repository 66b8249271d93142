"""``python -m benchharness.robots.descriptions [ROOT]``: rewrite the shipped URDFs."""

import sys
from pathlib import Path

from ...paths import robots_dir
from . import write_all

if __name__ == "__main__":
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else robots_dir()
    for p in write_all(root):
        print(p)
