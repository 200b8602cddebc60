"""verify.studies.generate_compiled: the shipped compiled objectives are what the generator prints from sympy now."""

from __future__ import annotations

import ast

import pytest
import sympy as sp

from verify.kernel import _generated_gains, compiled
from verify.studies.generate_compiled import GAINS_PATH, ROUTE_PATH, generated_sources
from verify.kernel import _generated_route


@pytest.fixture(scope="module")
def sources():
    return generated_sources()


def test_the_shipped_modules_are_the_generator_output(sources):
    """Regenerates both modules from the sympy derivation (a second of sympy) and compares the text."""
    if _generated_gains.SYMPY_VERSION != sp.__version__:
        pytest.skip(f"generated with sympy {_generated_gains.SYMPY_VERSION}, running {sp.__version__}")
    assert set(sources) == {GAINS_PATH, ROUTE_PATH}
    for path, text in sources.items():
        assert path.read_text() == text, f"{path.name} is stale: run `python -m verify.studies.generate_compiled`"


def test_the_modules_carry_the_hash_of_the_sources_they_were_printed_from(sources):
    for text in sources.values():
        assert f"SOURCE_HASH = {compiled.source_hash()!r}" in text


def test_identical_expressions_share_one_function():
    """The corrected law's |K_uu| and |K_rr| are both 1 / |sqrt(1 - e_o^2)| (by hand): one function pair."""
    terms = _generated_gains.TERMS[("corrected", -1)]
    assert terms[("k_abs", 0)] == terms[("k_abs", 8)] and callable(terms[("k_abs", 0)][0])
    names = [n.name for n in ast.parse(GAINS_PATH.read_text()).body if isinstance(n, ast.FunctionDef)]
    assert len(names) == len(set(names))


def test_every_bound_law_and_hemisphere_is_shipped():
    keys = set(_generated_route.OBJECTIVES)
    for name in ("L1", "L2", "xi_bar", "zeta_theta"):
        assert {(name, "", -1), (name, "", 1)} <= keys
    for name in compiled.LAW_BOUNDS:
        assert {(name, law, s) for law in ("paper", "corrected") for s in (-1, 1)} <= keys
    assert set(_generated_gains.TERMS) == {(law, s) for law in ("paper", "corrected") for s in (-1, 1)}
