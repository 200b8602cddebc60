"""A QOCO solver generated for one sparsity pattern (qocogen), compiled once per machine and loaded with ctypes.

qocogen (Chari & Açıkmeşe) writes a C solver specialised to one cone program's sparsity pattern: the KKT
factorisation unrolled over the pattern's symbolic LDL, no allocation, no branching on structure. This module
turns a :class:`~tubekit.fhocp.qp.base.ConeProgramData` into such a solver:

1. :func:`pattern_key` hashes what the generated code depends on (the patterns of P, of A's zero rows and of its
   cone rows, the cone, qocogen's version, the shim, the compiler and its flags, the machine);
2. :func:`build_solver` generates the C sources into a fresh directory under :func:`cache_root`, adds a small shim
   (:data:`SHIM`: a workspace per solver, every value array updated by pointer, no copy in Python), compiles one
   shared library with the system C compiler and moves the directory into place atomically. Processes that need
   the same key at once (a campaign's workers on their first period) take the key's build lock in turn (an
   ``flock`` on ``<key>.lock``, released when its holder exits, however it exits): one compiles, the others load
   what it built. Where ``fcntl`` is missing each builds its own and the rename keeps one directory;
3. :class:`GeneratedSolver` loads the library and solves with numpy buffers passed by pointer.

The cache is a build artefact, like numba's: ``TUBEKIT_QOCOGEN_CACHE`` names its root, else
``$XDG_CACHE_HOME/tubekit/qocogen`` (``~/.cache/tubekit/qocogen``). A build costs seconds (about 2.6 s of generation
and 7 s of compilation for the real-time FHOCP of the paper's scenario, 124 variables and 238 rows, on a 2-core
machine); every later process loads it in milliseconds. Needs ``pip install qocogen`` and a C compiler.
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import importlib.metadata
import importlib.util
import io
import logging
import os
import platform
import shutil
import subprocess
import tempfile
import time
from functools import lru_cache
from pathlib import Path
from typing import Iterator

import numpy as np
import scipy.sparse as sp

from tubekit.exceptions import NotAvailableError
from tubekit.fhocp.qp.base import ConeProgramData, zero_and_cone_rows

__all__ = ["SHIM", "COMPILE_FLAGS", "SETTING_DEFAULTS", "NO_COMPILER", "compiler", "cache_root", "pattern_key", "build_solver",
           "GeneratedSolver"]

#: The compiler's flags: the generated solver is specialised to its pattern, and the cache to its machine. Measured
#: on the paper's recorded subproblems (bare solve, median): -O1 0.46, -O2 0.28, -Os 0.32, -O3 0.30, -O3
#: -march=native 0.21, with -funroll-loops 0.20 ms. None of them reassociates floating-point operations.
COMPILE_FLAGS = ("-O3", "-march=native", "-funroll-loops", "-shared", "-fPIC", "-w")

#: The generated solver's settings and their defaults (qocogen's ``set_default_settings``); ints first.
SETTING_DEFAULTS: dict[str, int | float] = {
    "max_iters": 200, "bisect_iters": 5, "iter_ref_iters": 1,
    "kkt_static_reg": 1e-8, "kkt_dynamic_reg": 1e-8, "abstol": 1e-7, "reltol": 1e-7,
    "abstol_inacc": 1e-5, "reltol_inacc": 1e-5,
}

#: The C shim compiled beside the generated sources: a workspace per solver, settings, one solve by pointers.
SHIM = r"""
#include <stdlib.h>
#include <string.h>
#include "qoco_custom.h"
void* tk_new(void) {
  Workspace* w = (Workspace*)calloc(1, sizeof(Workspace));
  if (w) { set_default_settings(w); load_data(w); }
  return w;
}
void tk_free(void* w) { free(w); }
int tk_n(void* w) { return ((Workspace*)w)->n; }
void tk_settings(void* wv, int max_iters, int bisect_iters, int iter_ref_iters, double static_reg,
                 double dynamic_reg, double abstol, double reltol, double abstol_inacc, double reltol_inacc) {
  Workspace* w = (Workspace*)wv;
  w->settings.max_iters = max_iters; w->settings.bisect_iters = bisect_iters;
  w->settings.iter_ref_iters = iter_ref_iters; w->settings.kkt_static_reg = static_reg;
  w->settings.kkt_dynamic_reg = dynamic_reg; w->settings.abstol = abstol; w->settings.reltol = reltol;
  w->settings.abstol_inacc = abstol_inacc; w->settings.reltol_inacc = reltol_inacc; w->settings.verbose = 0;
}
int tk_solve(void* wv, double* P, double* A, double* G, double* c, double* b, double* h, double* x,
             double* info) {
  Workspace* w = (Workspace*)wv;
  if (P) update_P(w, P);
  if (A) update_A(w, A);
  if (b) update_b(w, b);
  update_G(w, G); update_c(w, c); update_h(w, h);
  qoco_custom_solve(w);
  memcpy(x, w->sol.x, sizeof(double) * (size_t)w->n);
  info[0] = w->sol.obj; info[1] = (double)w->sol.iters;
  return (int)w->sol.status;
}
"""

LOGGER = logging.getLogger(__name__)

#: What a machine without a C compiler is told (the backend's availability and the build say the same).
NO_COMPILER = ("the QP backend 'qocogen' needs a C compiler (cc, gcc or clang on PATH, or CC) to build its "
               "generated solver")

_SOURCES = ("qoco_custom.c", "cone.c", "utils.c", "ldl.c", "kkt.c", "tk_shim.c")
_LIBRARY = "libtubekit_qocogen.so"


@lru_cache(maxsize=1)
def compiler() -> tuple[str, str] | None:
    """The C compiler (``CC``, else ``cc``, ``gcc``, ``clang`` on PATH) and its version line; None without one."""
    for name in filter(None, (os.environ.get("CC"), "cc", "gcc", "clang")):
        path = shutil.which(name)
        if path is None:
            continue
        try:
            out = subprocess.run([path, "--version"], capture_output=True, text=True, timeout=30, check=False)
        except (OSError, subprocess.SubprocessError):
            continue
        if out.returncode == 0:
            return path, (out.stdout.splitlines() or [""])[0]
    return None


def cache_root() -> Path:
    """Where generated solvers are kept: ``TUBEKIT_QOCOGEN_CACHE``, else ``$XDG_CACHE_HOME/tubekit/qocogen``."""
    named = os.environ.get("TUBEKIT_QOCOGEN_CACHE")
    if named:
        return Path(named)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "tubekit" / "qocogen"


def _cpu() -> str:
    """The CPU's model name (``-march=native`` code is this CPU's), or the platform's processor string."""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith(("model name", "flags")):
                return line
    return platform.processor()


def pattern_key(data: ConeProgramData) -> str:
    """A hex digest of everything the generated library depends on (module doc, step 1)."""
    h = hashlib.sha256()
    found = compiler()
    for part in (repr((data.n, data.m, data.dims.zero, data.dims.nonneg, data.dims.soc, data.p_values is None)),
                 importlib.metadata.version("qocogen"), SHIM, repr(COMPILE_FLAGS), repr(found),
                 platform.machine(), _cpu()):
        h.update(part.encode())
    for array in (data.p_indices, data.p_indptr, data.a_indices, data.a_indptr):
        h.update(np.ascontiguousarray(array, dtype=np.int64).tobytes())
    return h.hexdigest()[:32]


def _blocks(data: ConeProgramData) -> tuple[sp.csc_matrix | None, sp.csc_matrix]:
    """A's zero rows and its other rows as matrices over their full patterns, every stored zero kept."""
    zero = data.dims.zero
    (pe, ie, qe), (pg, ig, qg) = zero_and_cone_rows(data)
    eq = sp.csc_matrix((data.a_values[pe].astype(float), ie, qe), shape=(zero, data.n)) if zero else None
    return eq, sp.csc_matrix((data.a_values[pg].astype(float), ig, qg), shape=(data.m - zero, data.n))


def _generate(data: ConeProgramData, where: Path) -> None:
    """qocogen's sources for ``data``'s pattern in ``where/solver`` (its progress prints swallowed)."""
    import qocogen

    eq, cone = _blocks(data)
    zero = data.dims.zero
    p = None if data.p_values is None else data.P()
    with contextlib.redirect_stdout(io.StringIO()):
        qocogen.generate_solver(data.n, data.m - zero, zero, p, np.array(data.q, dtype=float), eq,
                                np.array(data.b[:zero], dtype=float) if zero else None, cone,
                                np.array(data.b[zero:], dtype=float), data.dims.nonneg, len(data.dims.soc),
                                np.array(data.dims.soc, dtype=np.int32), output_dir=str(where), name="solver")


def build_solver(data: ConeProgramData) -> Path:
    """The compiled library for ``data``'s pattern: from the cache, else generated, compiled and cached.

    Raises
    ------
    NotAvailableError
        qocogen or a C compiler is missing, or the compiler failed (its last lines in the message).
    """
    found = compiler()
    if found is None:
        raise NotAvailableError(NO_COMPILER)
    final = cache_root() / pattern_key(data)
    if (final / _LIBRARY).is_file():
        return final / _LIBRARY
    final.parent.mkdir(parents=True, exist_ok=True)
    with _build_lock(final.with_name(final.name + ".lock")):
        if (final / _LIBRARY).is_file():  # another process built it while this one waited
            return final / _LIBRARY
        _build_into(data, final, found[0])
    return final / _LIBRARY


@contextlib.contextmanager
def _build_lock(path: Path) -> Iterator[None]:
    """An exclusive ``flock`` on ``path`` for the block (waiting for its holder; the kernel releases it when the
    holder's process ends); no lock where ``fcntl`` is missing (module doc, step 2)."""
    if importlib.util.find_spec("fcntl") is None:
        yield
        return
    import fcntl
    with open(path, "a+b") as handle:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle.fileno(), fcntl.LOCK_UN)


def _build_into(data: ConeProgramData, final: Path, cc: str) -> None:
    """Generate ``data``'s solver, compile it with ``cc`` and move it into ``final`` (module doc, step 2)."""
    scratch = Path(tempfile.mkdtemp(prefix=".build-", dir=final.parent))
    LOGGER.info("qocogen: generating and compiling a solver for this subproblem's pattern (%d variables, %d rows; "
                "once per machine, seconds) into %s", data.n, data.m, final)
    started = time.perf_counter()
    try:
        _generate(data, scratch)
        src = scratch / "solver"
        (src / "tk_shim.c").write_text(SHIM)
        cmd = [cc, *COMPILE_FLAGS, "-o", str(src / _LIBRARY), *(str(src / s) for s in _SOURCES), "-lm"]
        out = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if out.returncode != 0:
            tail = "\n".join(out.stderr.splitlines()[-5:])
            raise NotAvailableError(f"the QP backend 'qocogen' could not compile its generated solver:\n{tail}")
        try:
            os.rename(src, final)  # atomic; fails if another process put the same key in place first
        except OSError:
            if not (final / _LIBRARY).is_file():
                raise
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    LOGGER.info("qocogen: solver ready after %.1f s", time.perf_counter() - started)


class GeneratedSolver:
    """The generated solver of one pattern, loaded from ``library`` with a workspace and value buffers of its own.

    Parameters
    ----------
    library : Path
        The library :func:`build_solver` made for ``pattern``.
    pattern : ConeProgramData
        A program of the pattern (its values are not used): sizes, and where A's zero and cone rows sit in its values.
    settings : mapping
        Values for every name of :data:`SETTING_DEFAULTS`.

    Raises
    ------
    NotAvailableError
        The library was built for another number of variables (a stale cache entry).
    """

    def __init__(self, library: Path, pattern: ConeProgramData, settings: dict[str, int | float]) -> None:
        lib = ctypes.CDLL(str(library))
        lib.tk_new.restype = ctypes.c_void_p
        lib.tk_free.argtypes = [ctypes.c_void_p]
        lib.tk_n.argtypes = [ctypes.c_void_p]
        lib.tk_settings.argtypes = [ctypes.c_void_p] + [ctypes.c_int] * 3 + [ctypes.c_double] * 6
        lib.tk_solve.argtypes = [ctypes.c_void_p] * 9
        lib.tk_solve.restype = ctypes.c_int
        self._lib = lib
        self._work = lib.tk_new()
        if not self._work:
            raise MemoryError("the generated solver could not allocate its workspace")
        n, zero, m = pattern.n, pattern.dims.zero, pattern.m
        if lib.tk_n(self._work) != n:
            raise NotAvailableError(f"the cached qocogen solver at {library} has {lib.tk_n(self._work)} variables, "
                                    f"not {n}: remove that directory")
        values = [settings[k] for k in SETTING_DEFAULTS]
        lib.tk_settings(self._work, *(int(v) for v in values[:3]), *(float(v) for v in values[3:]))
        (self._eq, _, _), (self._cone, _, _) = zero_and_cone_rows(pattern)
        self._zero = zero
        self._has_p = pattern.p_values is not None
        #: the value buffers the library reads (P, A's zero rows, A's cone rows, q, b's zero and cone parts), x, info
        self._buffers = [np.zeros(len(pattern.p_indices)), np.zeros(len(self._eq)), np.zeros(len(self._cone)),
                         np.zeros(n), np.zeros(zero), np.zeros(m - zero), np.zeros(n), np.zeros(2)]
        self._pointers = [int(buf.ctypes.data) if buf.size else None for buf in self._buffers]
        if not self._has_p:
            self._pointers[0] = None
        if not zero:
            self._pointers[1] = self._pointers[4] = None

    @property
    def x(self) -> np.ndarray:
        """The last solve's primal solution (n,), overwritten by the next solve."""
        return self._buffers[6]

    def solve(self, data: ConeProgramData) -> tuple[int, float, int]:
        """Solve ``data`` (of the pattern): (status code, objective without the offset, iterations)."""
        p, a, g, q, b, h, _, info = self._buffers
        if self._has_p:
            p[:] = data.p_values
        np.take(data.a_values, self._eq, out=a)
        np.take(data.a_values, self._cone, out=g)
        q[:] = data.q
        b[:] = data.b[:self._zero]
        h[:] = data.b[self._zero:]
        status = self._lib.tk_solve(self._work, *self._pointers)
        return int(status), float(info[0]), int(info[1])

    def __del__(self) -> None:
        work, self._work = getattr(self, "_work", None), None
        if work:
            self._lib.tk_free(work)
