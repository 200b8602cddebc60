"""The shipped symbolic forms (verify.lemma1.forms): used only for exactly the input they were computed from."""

from __future__ import annotations

import sympy as sp

from verify.lemma1 import forms
from verify.lemma1.polar import E_D, E_O, polar_hash, polar_model


def _fail(M):
    raise AssertionError("computed although the shipped table holds this input")


def test_a_stored_form_is_read_without_computing_and_equals_the_computation():
    J = polar_model(-1).J
    gram = forms.simplified("gram", J, _fail)  # J's Gram matrix is in the table (the J_lower / JK objectives)
    direct = (J.T * J).applyfunc(sp.simplify)
    assert (gram - direct).applyfunc(sp.simplify) == sp.zeros(3, 3)


def test_an_input_not_in_the_table_is_computed():
    M = sp.Matrix([[E_D, E_O], [0, 1 + E_D]])  # no objective of the bounds
    calls = []
    out = forms.simplified("gram", M, lambda A: calls.append(A) or (A.T * A).applyfunc(sp.simplify))
    assert calls == [M] and out == (M.T * M).applyfunc(sp.simplify)


def test_the_key_depends_on_kind_and_on_the_exact_expression():
    M = sp.Matrix([[E_D, 0], [0, 1]])
    assert forms.matrix_key("gram", M) != forms.matrix_key("sym", M)
    assert forms.matrix_key("gram", M) != forms.matrix_key("gram", M.subs(E_D, 2 * E_D))
    assert forms.matrix_key("gram", M) == forms.matrix_key("gram", sp.ImmutableMatrix(M))


def test_the_polar_model_is_stored_only_under_the_current_hash():
    assert forms.stored_polar(-1, "0" * 64) is None
    stored = forms.stored_polar(-1, polar_hash())
    assert stored is not None, "run `python -m verify.lemma1.generate`"
    assert set(stored) == set(forms.POLAR_FIELDS) | {"zeta_rotation_form"}
    assert stored["J"] == polar_model(-1).J


def test_recording_switches_the_table_off_and_collects_what_is_computed():
    J = polar_model(1).J
    forms.recording(True)
    try:
        calls = []
        forms.simplified("gram", J, lambda A: calls.append(A) or (A.T * A).applyfunc(sp.simplify))
        assert forms.stored_polar(1, polar_hash()) is None
    finally:
        record = forms.recording(False)
    assert len(calls) == 1 and forms.matrix_key("gram", J) in record
    assert forms.stored_polar(1, polar_hash()) is not None
