"""Re-checks, studies and tools built on the certificate: :mod:`~verify.studies.recheck` (with
:mod:`~verify.studies.rederive`), :mod:`~verify.studies.envelope`, :mod:`~verify.studies.region_search`
and the code generator :mod:`~verify.studies.generate_compiled`.

They import the certificate and the theorem, never the falsifiers (``tests/test_architecture.py``).
"""

__all__: list[str] = []
