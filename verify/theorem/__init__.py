"""The theorem: gain bounds over R (:mod:`~verify.theorem.gains`), the sampled-data tube and margins
(:mod:`~verify.theorem.sampled`), the design and its conditions (:mod:`~verify.theorem.design`), the
workspace conditions (:mod:`~verify.theorem.workspace`) and the tiers (:mod:`~verify.theorem.tiers`).

Beside it, in their own subpackages, the backup law's proof (:mod:`verify.backup`) and the dynamic
vehicle's loop bound (:mod:`verify.vehicle`). The theorem imports the kernel, never the certificate
artefact, the studies or the falsifiers (``tests/test_architecture.py``).
"""

__all__: list[str] = []
