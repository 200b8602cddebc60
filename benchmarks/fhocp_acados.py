"""An acados-shaped reference beside the real-time SCP step, interleaved on the paper scenario's states.

Each step is timed whole (for acados: setting x0 and the stage parameters from Python, ``solve``, reading
u_0) and, beside it, the bare solver (Clarabel's ``solve()`` calls; acados's own ``time_tot``).

Usage::

    python benchmarks/fhocp_acados.py [--duration S] [--horizons 8 16 32 64] [--qp-solvers clarabel qocogen]
        [--json FILE] [--acados-path DIR]

acados comes from the third-party wheel ``comma-deps-acados`` (the acados, HPIPM and BLASFEO libraries,
``acados_template`` and the tera renderer; the solver's C code is generated and compiled with the
system's gcc). **Install it into its own directory**: ``pip install --no-deps --target DIR
comma-deps-acados``, then ``--acados-path DIR``. The wheel vendors a slimmed CasADi 3.6.7 in the same
``casadi/`` package directory, so installed into site-packages it overwrites the CasADi the IPOPT peer
needs (its IPOPT plugin then fails to load); the script appends DIR to ``sys.path``, after the real CasADi.
The wheel lays its files out differently from an acados
checkout, so the script links them into a temporary ``ACADOS_SOURCE_DIR`` and preloads the libraries.

The reference is **acados-shaped, not the same problem**: 4 states [x, y, z, psi], 3 inputs [u, w, r],
the unicycle kinematics (ERK4, one step per dt), a nonlinear least-squares cost on the position error to
p_d(t + k dt) and the inputs, input bounds, two soft ball-exclusion constraints (L1 + L2 slack penalties)
for the two nearest obstacles, SQP-RTI with Gauss-Newton and HPIPM (partial condensing). It has no
e_d / e_o rows, no terminal set, no rate rows: it shows what a compiled structure-exploiting real-time
step costs for a problem of this shape, nothing about equal answers.

The closed-loop states are those of ``benchmarks/fhocp.py`` (real-time SCP, current, RK4); at every
state both steps run, the order alternated, each warm-started from its own previous step.
"""

from __future__ import annotations

import argparse
import ctypes
import gc
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = ["acados_root", "build_acados", "measure", "main"]

_LIBS = ("libblasfeo.so", "libhpipm.so", "libqpOASES_e.so.3.1", "libacados.so")


def acados_root() -> Path:
    """A temporary ACADOS_SOURCE_DIR laid out as acados expects, from the wheel's files; libraries preloaded."""
    import acados
    src = Path(acados.__file__).parent
    root = Path(tempfile.mkdtemp(prefix="acados_root_"))
    (root / "interfaces" / "acados_template").mkdir(parents=True)
    (root / "interfaces" / "acados_template" / "acados_template").symlink_to(src / "acados_template")
    for sub in ("lib", "include", "bin", "cmake"):
        (root / sub).symlink_to(src / "install" / sub)
    for lib in _LIBS:
        ctypes.CDLL(str(src / "install" / "lib" / lib), mode=ctypes.RTLD_GLOBAL)
    os.environ["ACADOS_SOURCE_DIR"] = str(root)
    return root


def build_acados(n: int, dt: float, limits: np.ndarray, weights: tuple, workdir: Path):
    """The SQP-RTI solver of the module doc for horizon ``n``; returns the AcadosOcpSolver."""
    import casadi as ca
    from acados.acados_template import AcadosModel, AcadosOcp, AcadosOcpSolver

    q, r, pw = weights
    m = AcadosModel()
    m.name = f"unicycle_n{n}"
    x, u, p = ca.SX.sym("x", 4), ca.SX.sym("u", 3), ca.SX.sym("p", 11)  # p_d, (c, r + clearance) x 2
    m.x, m.u, m.p = x, u, p
    m.f_expl_expr = ca.vertcat(u[0] * ca.cos(x[3]), u[0] * ca.sin(x[3]), u[1], u[2])
    m.xdot = ca.SX.sym("xdot", 4)
    m.f_impl_expr = m.xdot - m.f_expl_expr
    m.con_h_expr = ca.vertcat(ca.sumsqr(x[:3] - p[3:6]) - p[6] ** 2, ca.sumsqr(x[:3] - p[7:10]) - p[10] ** 2)
    m.cost_y_expr = ca.vertcat(x[:3] - p[:3], u)
    m.cost_y_expr_e = x[:3] - p[:3]
    ocp = AcadosOcp()
    ocp.model = m
    ocp.dims.N = n
    ocp.cost.cost_type = ocp.cost.cost_type_e = "NONLINEAR_LS"
    ocp.cost.W = np.diag([q[0], q[0], q[1], r[0], r[1], r[2]]) * dt
    ocp.cost.W_e = np.diag([pw[0], pw[0], pw[1]])
    ocp.cost.yref, ocp.cost.yref_e = np.zeros(6), np.zeros(3)
    ocp.parameter_values = np.zeros(11)
    ocp.constraints.lbu, ocp.constraints.ubu, ocp.constraints.idxbu = -limits, limits, np.arange(3)
    ocp.constraints.lh, ocp.constraints.uh = np.zeros(2), 1e8 * np.ones(2)
    ocp.constraints.idxsh = np.arange(2)
    ocp.cost.zl = ocp.cost.zu = 1e3 * np.ones(2)
    ocp.cost.Zl = ocp.cost.Zu = np.ones(2)
    ocp.constraints.x0 = np.zeros(4)
    o = ocp.solver_options
    o.tf, o.qp_solver, o.hessian_approx, o.integrator_type = n * dt, "PARTIAL_CONDENSING_HPIPM", "GAUSS_NEWTON", "ERK"
    o.nlp_solver_type, o.sim_method_num_stages, o.sim_method_num_steps = "SQP_RTI", 4, 1
    o.code_export_directory = str(workdir / f"c_generated_n{n}")
    cwd = os.getcwd()
    os.chdir(workdir)  # acados writes some generated files into the working directory
    try:
        return AcadosOcpSolver(ocp, json_file=str(workdir / f"ocp_n{n}.json"), verbose=False)
    finally:
        os.chdir(cwd)


def _params(scenario, t: float, k: int, dt: float, obstacles: list, clearance: float) -> np.ndarray:
    """Stage k's parameters: p_d(t + k dt) and the two nearest obstacles (far away when fewer)."""
    pd = np.asarray(scenario.trajectory.position(np.array([t + k * dt])), dtype=float).reshape(3)
    obs = [(np.asarray(o.center, dtype=float), o.radius + clearance) for o in obstacles[:2]]
    obs += [(pd + 50.0, 1.0)] * (2 - len(obs))  # inactive: 50 m away
    return np.concatenate([pd, obs[0][0], [obs[0][1]], obs[1][0], [obs[1][1]]])


def measure(duration: float, horizons: tuple[int, ...], qp_solvers: tuple[str, ...] = ("clarabel",)) -> dict:
    """Interleaved steps per horizon: the real-time SCP step on each QP backend of ``qp_solvers`` (the first is
    ``scp_realtime``, the others ``scp_realtime_<name>``) and the acados SQP-RTI step (ms); the order rotates from
    state to state."""
    sys.path.insert(0, str(Path(__file__).parent))
    import dataclasses
    from fhocp import benchmark_tightening, closed_loop  # the v2 benchmark's closed loop and tightening

    from tubekit import paper_scenario
    from tubekit.fhocp import FHOCP, ScpOptions

    acados_root()
    workdir = Path(tempfile.mkdtemp(prefix="acados_build_"))
    base = paper_scenario()
    tg = benchmark_tightening(base)
    states = closed_loop(base, tg, duration)
    out: dict = {"states": len(states) - 1, "by_horizon": {}}
    for n in horizons:
        sc = dataclasses.replace(base, controller=dataclasses.replace(base.controller, horizon_steps=n))
        dt = sc.controller.dt
        ctrls = {("scp_realtime" if i == 0 else f"scp_realtime_{qp}"):
                 FHOCP(sc, tg, mode="realtime", options=ScpOptions(qp_solver=qp)) for i, qp in enumerate(qp_solvers)}
        weights = (tuple(sc.controller.Q), tuple(sc.controller.R), tuple(sc.controller.P))
        b0 = time.perf_counter()
        aca = build_acados(n, dt, np.asarray(sc.limits.vector, dtype=float),
                           (weights[0][:2], weights[1], weights[2][:2]), workdir)
        build_s = time.perf_counter() - b0
        clearance = sc.vehicle_radius + tg.obstacle_margin
        names = (*ctrls, "acados_sqp_rti")
        times: dict[str, list[float]] = {k: [] for k in names}
        bare: dict[str, list[float]] = {k: [] for k in names}
        failures = 0
        for i, (t, s, obs) in enumerate(states):
            gc.collect()
            order = names[i % len(names):] + names[:i % len(names)]
            for name in order:
                t0 = time.perf_counter()
                if name != "acados_sqp_rti":
                    solver_s = ctrls[name].solve(t, s, obs).solver_time_s
                else:
                    aca.set(0, "lbx", s)
                    aca.set(0, "ubx", s)
                    for k in range(n + 1):
                        aca.set(k, "p", _params(sc, t, k, dt, list(obs), clearance))
                    failures += int(aca.solve() != 0) if i > 0 else 0
                    aca.get(0, "u")
                    solver_s = float(np.ravel(aca.get_stats("time_tot"))[0])
                el = time.perf_counter() - t0
                if i > 0:
                    times[name].append(el)
                    bare[name].append(solver_s)
        row: dict = {k: {"median_ms": float(np.median(v) * 1e3), "p99_ms": float(np.percentile(v, 99) * 1e3),
                         "solver_median_ms": float(np.median(bare[k]) * 1e3)} for k, v in times.items()}
        row["acados_failures"] = failures
        row["acados_build_s"] = build_s
        for name in ctrls:
            key = "scp_over_acados" if name == "scp_realtime" else f"{name}_over_acados"
            row[key] = row[name]["median_ms"] / row["acados_sqp_rti"]["median_ms"]
        out["by_horizon"][n] = row
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=20.0, help="closed-loop seconds replayed (default 20)")
    ap.add_argument("--horizons", type=int, nargs="+", default=[8, 16, 32, 64], help="horizons N")
    ap.add_argument("--json", type=Path, help="write the results to this JSON file")
    ap.add_argument("--acados-path", type=Path, help="the --target directory comma-deps-acados was installed into")
    ap.add_argument("--qp-solvers", nargs="+", default=["clarabel"],
                    help="the real-time SCP's QP backends, each a method of its own (default clarabel; e.g. clarabel "
                         "qocogen)")
    args = ap.parse_args(argv)
    if args.acados_path is not None:
        sys.path.append(str(args.acados_path))
    try:
        import acados  # noqa: F401
        import casadi  # noqa: F401
    except ImportError:
        print("acados is absent: pip install --no-deps --target DIR comma-deps-acados, then --acados-path DIR "
              "(acados_template itself is not on the package index here and ships no libraries)", file=sys.stderr)
        return 1
    res = measure(args.duration, tuple(args.horizons), tuple(args.qp_solvers))
    text = json.dumps(res, indent=2)
    print(text)
    if args.json:
        from tubekit.jsonable import write_text

        write_text(args.json, text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
