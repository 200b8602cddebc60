"""tubekit.fhocp.qp.generated: the generated solver's pattern key, its cache, its build and its loading."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tubekit import NotAvailableError
from tubekit.fhocp.qp import generated
from tubekit.fhocp.qp.base import ConeDims, ConeProgramData

pytest.importorskip("qocogen")
if generated.compiler() is None:
    pytest.skip("no C compiler for the generated solver", allow_module_level=True)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("TUBEKIT_QOCOGEN_CACHE", str(tmp_path))
    return tmp_path


def _program(values=(1.0, -1.0, 1.0, -1.0), zero: int = 1) -> ConeProgramData:
    """min 1/2|x|^2 - x_0 s.t. x_0 = x_1 (zero rows: ``zero``), x_0 <= 1, x_1 >= -1; A's values ``values``."""
    A = np.array([[values[0], values[1]], [values[2], 0.0], [0.0, values[3]]])
    return ConeProgramData.from_matrices(np.eye(2), [-1.0, 0.0], A, [0.0, 1.0, 1.0],
                                         ConeDims(zero=zero, nonneg=3 - zero))


def test_the_key_depends_on_the_pattern_and_the_cone_not_on_the_values():
    base = generated.pattern_key(_program())
    assert generated.pattern_key(_program((2.0, -3.0, 0.5, -1.0))) == base
    assert generated.pattern_key(dataclasses.replace(_program(), q=np.array([5.0, 5.0]))) == base
    assert generated.pattern_key(_program(zero=0)) != base                      # the cone
    sparser = ConeProgramData.from_matrices(np.eye(2), [-1.0, 0.0], np.array([[1.0, 0.0], [1.0, 0.0], [0.0, -1.0]]),
                                            [0.0, 1.0, 1.0], ConeDims(zero=1, nonneg=2))
    assert generated.pattern_key(sparser) != base                               # A's pattern
    assert generated.pattern_key(dataclasses.replace(_program(), p_values=None)) != base  # P = 0


def test_the_cache_root_is_the_named_directory_else_the_users_cache(monkeypatch, tmp_path):
    monkeypatch.setenv("TUBEKIT_QOCOGEN_CACHE", str(tmp_path / "mine"))
    assert generated.cache_root() == tmp_path / "mine"
    monkeypatch.delenv("TUBEKIT_QOCOGEN_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert generated.cache_root() == tmp_path / "xdg" / "tubekit" / "qocogen"


def test_a_pattern_is_built_once_and_loaded_afterwards(cache, caplog):
    with caplog.at_level("INFO", logger="tubekit.fhocp.qp.generated"):
        library = generated.build_solver(_program())
    assert "compiling a solver for this subproblem's pattern (2 variables, 3 rows; once per machine" in caplog.text
    caplog.clear()
    stamp = library.stat().st_mtime_ns
    with caplog.at_level("INFO", logger="tubekit.fhocp.qp.generated"):
        again = generated.build_solver(_program((2.0, -3.0, 0.5, -1.0)))     # the same pattern, other values
    assert again == library and again.stat().st_mtime_ns == stamp and caplog.text == ""
    assert [p.name for p in cache.iterdir()] == [library.parent.name]   # no scratch directory left behind
    data = _program()
    solver = generated.GeneratedSolver(library, data, dict(generated.SETTING_DEFAULTS))
    code, objective, _ = solver.solve(data)
    # min 1/2|x|^2 - x_0 on x_0 = x_1: x = (1/2, 1/2), objective -1/4
    assert code == 1 and solver.x == pytest.approx([0.5, 0.5], abs=1e-6) and objective == pytest.approx(-0.25, abs=1e-6)


def test_a_library_of_another_size_is_refused_by_name(cache):
    library = generated.build_solver(_program())
    three = ConeProgramData.from_matrices(np.eye(3), np.zeros(3), np.eye(3), np.ones(3), ConeDims(nonneg=3))
    with pytest.raises(NotAvailableError, match=r"has 2 variables, not 3: remove that directory"):
        generated.GeneratedSolver(library, three, dict(generated.SETTING_DEFAULTS))


def test_a_failed_compilation_is_reported_with_the_compilers_words_and_leaves_nothing(cache, monkeypatch):
    monkeypatch.setattr(generated, "COMPILE_FLAGS", ("--no-such-flag-for-any-compiler",))
    with pytest.raises(NotAvailableError, match=r"could not compile its generated solver:\n.*no-such-flag"):
        generated.build_solver(_program())
    assert list(cache.iterdir()) == []


def test_without_a_compiler_the_build_names_what_is_missing(cache, monkeypatch):
    monkeypatch.setattr(generated, "compiler", lambda: None)
    with pytest.raises(NotAvailableError, match=r"needs a C compiler \(cc, gcc or clang on PATH, or CC\)"):
        generated.build_solver(_program())


def test_a_key_another_process_put_in_place_first_is_used(cache, monkeypatch):
    """Two builders of one key: the rename of the second fails on the first's directory, and its library is used."""
    data = _program()
    first = generated.build_solver(data)
    real_is_file = type(first).is_file
    calls = {"n": 0}

    def missing_once(path):  # the first look finds nothing, as if the other process had not finished yet
        calls["n"] += 1
        return False if calls["n"] == 1 else real_is_file(path)

    monkeypatch.setattr(type(first), "is_file", missing_once)
    assert generated.build_solver(data) == first
    assert sorted(p.name for p in cache.iterdir()) == [first.parent.name]
