"""The shipped module verify.lemma1._generated_forms equals a fresh derivation (verify.lemma1.generate)."""

from __future__ import annotations

import pytest
import sympy as sp

from verify.lemma1 import _generated_forms as shipped
from verify.lemma1.generate import GENERATED_PATH, generated_source
from verify.lemma1.polar import polar_hash


@pytest.mark.slow
def test_the_shipped_forms_are_the_derivation():
    """Regenerates everything with the table off (seconds of sympy) and compares the text."""
    if shipped.SYMPY_VERSION != sp.__version__:
        pytest.skip(f"forms generated with sympy {shipped.SYMPY_VERSION}, running {sp.__version__}")
    assert generated_source() == GENERATED_PATH.read_text(), "run `python -m verify.lemma1.generate`"


def test_the_shipped_forms_carry_the_current_hash():
    assert shipped.POLAR_HASH == polar_hash(), "run `python -m verify.lemma1.generate`"
    assert set(shipped.POLAR) == {-1, 1}
