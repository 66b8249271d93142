"""``torch.rand`` of a seeded CPU ``torch.Generator``, in NumPy: the IK restarts without torch.

Why: the IK's random restarts have always been drawn from a
``torch.Generator`` (``torch.Generator().manual_seed(seed)`` and
``torch.rand(n, dof, dtype=float64)``). Rubik's trials otherwise need no
torch, and importing it costs every run command ~2 CPU-s (issue 12); the
stream is reproduced here bit for bit, so no result changes.

torch's CPU generator is a 32-bit Mersenne Twister (MT19937) seeded by the
reference ``init_genrand`` with the seed's low 32 bits; a float64 uniform
takes two outputs ``a``, ``b`` as ``((a << 32) | b) & (2**53 - 1)`` times
``2**-53``, one element after another. NumPy's ``MT19937`` bit generator is
the same twister; its state is set from ``init_genrand`` directly
(``tests/robots/test_urdf_chain.py`` compares the streams with torch's).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = ["UniformStream"]

_MASK53 = np.uint64((1 << 53) - 1)


@lru_cache(maxsize=16)
def _init_genrand(seed: int) -> tuple[int, ...]:
    """The reference MT19937 seeding (Matsumoto and Nishimura's ``init_genrand``)."""
    key = [seed & 0xFFFFFFFF]
    for i in range(1, 624):
        prev = key[-1]
        key.append((1812433253 * (prev ^ (prev >> 30)) + i) & 0xFFFFFFFF)
    return tuple(key)


class UniformStream:
    """A seeded stream of float64 uniforms in [0, 1), identical to a ``torch.Generator``'s ``torch.rand``."""

    def __init__(self, seed: int = 0) -> None:
        self.manual_seed(seed)

    def manual_seed(self, seed: int) -> UniformStream:
        """Restart the stream at ``seed`` (as ``torch.Generator.manual_seed``); returns the stream."""
        self._bits = np.random.MT19937(0)  # its seeding is replaced by the state below
        self._bits.state = {
            "bit_generator": "MT19937",
            "state": {"key": np.array(_init_genrand(int(seed)), dtype=np.uint32), "pos": 624},
        }
        return self

    def rand(self, *shape: int) -> np.ndarray:
        """Uniforms of ``shape``, as ``torch.rand(*shape, generator=g, dtype=torch.float64)``."""
        n = int(np.prod(shape, dtype=np.int64))
        raw = self._bits.random_raw(2 * n)
        bits = (raw[0::2] << np.uint64(32)) | raw[1::2]
        return ((bits & _MASK53).astype(np.float64) * 2.0**-53).reshape(shape)
