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
    # no scratch directory left behind: the library's directory and its key's build lock
    assert sorted(p.name for p in cache.iterdir()) == [library.parent.name, library.parent.name + ".lock"]
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
    assert [p.name for p in cache.iterdir()] == [generated.pattern_key(_program()) + ".lock"]  # no directory


def test_without_a_compiler_the_build_names_what_is_missing(cache, monkeypatch):
    monkeypatch.setattr(generated, "compiler", lambda: None)
    with pytest.raises(NotAvailableError, match=r"needs a C compiler \(cc, gcc or clang on PATH, or CC\)"):
        generated.build_solver(_program())


def test_a_key_another_process_put_in_place_first_is_used(cache, monkeypatch):
    """Two builders of one key without the lock (no ``fcntl``): the rename of the second fails on the first's
    directory, and its library is used."""
    data = _program()
    first = generated.build_solver(data)
    real_is_file = type(first).is_file
    calls = {"n": 0}

    def missing_twice(path):  # both looks (before and under the lock) find nothing, as if the other were not done
        calls["n"] += 1
        return False if calls["n"] <= 2 else real_is_file(path)

    monkeypatch.setattr(type(first), "is_file", missing_twice)
    assert generated.build_solver(data) == first
    assert sorted(p.name for p in cache.iterdir()) == [first.parent.name, first.parent.name + ".lock"]


def test_a_builder_waits_for_the_keys_lock_and_loads_what_its_holder_built(cache, monkeypatch):
    """While another process holds the key's build lock, a builder that found no library waits for it, then loads
    the library the holder put in place and compiles nothing."""
    import fcntl
    import threading
    data = _program()
    final = cache / generated.pattern_key(data)
    monkeypatch.setattr(generated, "_build_into", lambda *args: pytest.fail("compiled what the holder built"))
    asking, real_flock = threading.Event(), fcntl.flock

    def flock(fd, op):  # the builder has looked for the library (none yet) and asks for the lock
        if threading.current_thread() is not threading.main_thread():
            asking.set()
        return real_flock(fd, op)
    monkeypatch.setattr(fcntl, "flock", flock)
    outcome: list[object] = []

    def build() -> None:
        try:
            outcome.append(generated.build_solver(data))
        except BaseException as exc:  # reported by the main thread
            outcome.append(exc)
    with open(final.with_name(final.name + ".lock"), "a+b") as held:  # another open file: another lock holder
        real_flock(held.fileno(), fcntl.LOCK_EX)
        builder = threading.Thread(target=build)
        builder.start()
        while not asking.wait(0.05) and builder.is_alive():  # a builder that never asks ends (and fails) instead
            pass
        final.mkdir()
        (final / generated._LIBRARY).write_bytes(b"built by the holder")
        real_flock(held.fileno(), fcntl.LOCK_UN)
    builder.join()
    assert outcome == [final / generated._LIBRARY]
