"""The exception hierarchy: one base, narrow subclasses that are also built-ins."""

from __future__ import annotations

import pytest

from tubekit.exceptions import ConfigError, NotAvailableError, ShapeError, SolverError, TubekitError


@pytest.mark.parametrize("cls, builtin", [(ConfigError, ValueError), (ShapeError, ValueError),
                                          (SolverError, RuntimeError), (NotAvailableError, RuntimeError)])
def test_subclasses_base_and_builtin(cls, builtin):
    assert issubclass(cls, TubekitError) and issubclass(cls, builtin)


def test_config_error_message_names_field_expected_received_and_hint():
    exc = ConfigError("limits.u_max", "a number > 0", -1, "use m/s")
    assert str(exc) == "limits.u_max: expected a number > 0, received -1. use m/s"
    assert (exc.field, exc.expected, exc.received) == ("limits.u_max", "a number > 0", -1)


def test_shape_error_keeps_its_parts():
    exc = ShapeError("state", "(4,)", (3,))
    assert "state" in str(exc) and "(4,)" in str(exc) and "(3,)" in str(exc)
    assert (exc.name, exc.expected, exc.received) == ("state", "(4,)", (3,))
