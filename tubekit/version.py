"""The one version string of tubekit and verify (pyproject reads it too)."""

__all__ = ["__version__"]

__version__ = "0.1.0"
