"""A tiny pseudo-random generator whose output is pinned forever.

The protocol needs "same seed → same sequences" on every platform, NumPy and
Python version. NumPy's ``Generator`` does not promise stream stability across
releases and ``random.Random`` is an implementation detail of CPython, so the
generator is written out here over plain Python integers, where every
operation is exact and defined:

* :func:`fnv1a_64` — FNV-1a, 64-bit (offset basis 0xcbf29ce484222325, prime
  0x100000001b3), hashes a text key to a 64-bit seed;
* :class:`SplitMix64` — Steele, Lea & Flood's SplitMix64 (the seeding generator
  of xoshiro), one 64-bit word per step;
* :meth:`SplitMix64.below` — a uniform integer in ``[0, n)`` by rejection: draw
  ``x``; reject it while ``x >= 2**64 - (2**64 % n)``; return ``x % n``. The
  rejection removes the modulo bias exactly.

Both are a few lines in any language, so a third party can reproduce the
benchmark's sequences without this package. Known-answer tests pin them.
"""

from __future__ import annotations

MASK64 = (1 << 64) - 1
_FNV_OFFSET = 0xCBF29CE484222325
_FNV_PRIME = 0x100000001B3
_GOLDEN = 0x9E3779B97F4A7C15


def fnv1a_64(data: bytes | str) -> int:
    """FNV-1a 64-bit hash of ``data`` (text is encoded as UTF-8)."""
    if isinstance(data, str):
        data = data.encode("utf-8")
    h = _FNV_OFFSET
    for byte in data:
        h = ((h ^ byte) * _FNV_PRIME) & MASK64
    return h


class SplitMix64:
    """SplitMix64 over Python ints; each instance is an independent stream."""

    __slots__ = ("state",)

    def __init__(self, seed: int) -> None:
        if not 0 <= seed <= MASK64:
            raise ValueError("SplitMix64 seed must be in [0, 2**64)")
        self.state = seed

    def next_u64(self) -> int:
        self.state = (self.state + _GOLDEN) & MASK64
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK64
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK64
        return z ^ (z >> 31)

    def below(self, n: int) -> int:
        """Uniform integer in ``[0, n)``, unbiased (rejection sampling)."""
        if not 1 <= n <= MASK64:
            raise ValueError("n must be in [1, 2**64)")
        limit = (1 << 64) - ((1 << 64) % n)
        while True:
            x = self.next_u64()
            if x < limit:
                return x % n
