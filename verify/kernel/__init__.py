"""The Arb kernel of verify: interval arithmetic (:mod:`~verify.kernel.intervals`), the region R
(:mod:`~verify.kernel.region`), the compiled objectives (:mod:`~verify.kernel.compiled`) and the strict
JSON readers every ``from_dict`` uses (:mod:`~verify.kernel.parts`).

The bottom role of verify: it imports no other role of verify (``tests/test_architecture.py``).
"""

__all__: list[str] = []
