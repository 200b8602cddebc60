"""Shared test configuration: hypothesis profiles and the reduced-size flag.

Profiles: ``ci`` (default; derandomized, quick) and ``thorough``
(``pytest --hypothesis-profile=thorough``).
"""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")

from hypothesis import HealthCheck, settings  # noqa: E402

settings.register_profile(
    "ci", derandomize=True, max_examples=40, deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "thorough", derandomize=False, max_examples=1000, deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# Tutorials and examples honour this flag to run at reduced sizes in the test suite.
os.environ.setdefault("TUBEKIT_QUICK", "1")
