"""The envelope figure's file check (the figure itself is drawn in tests/test_verify_studies_envelope.py)."""

from __future__ import annotations

import pytest

from tubekit.app.plots_envelope import plot_envelope
from tubekit.exceptions import ConfigError


def test_plot_envelope_refuses_a_missing_directory_before_drawing(tmp_path):
    with pytest.raises(ConfigError, match=r"^--plot: expected a file in an existing directory"):
        plot_envelope(object(), tmp_path / "missing" / "env.png")
    assert not (tmp_path / "missing").exists()


def test_the_old_home_still_exports_it():
    from tubekit.app import plots

    assert plots.plot_envelope is plot_envelope
