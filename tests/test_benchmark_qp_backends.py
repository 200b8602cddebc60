"""benchmarks/qp_backends.py: the QP backends on the FHOCP's recorded subproblems and in the certified tube run."""

from __future__ import annotations

import os

import pytest

import verify
from tubekit.fhocp.qp.generated import compiler
from tubekit.scenario import load_scenario

from .scripts import load_script

STUDY = load_script("benchmarks/qp_backends.py", "qp_backends_benchmark")

pytest.importorskip("qocogen")
if compiler() is None:
    pytest.skip("no C compiler for the generated solver", allow_module_level=True)


@pytest.fixture(scope="module", autouse=True)
def cache(tmp_path_factory):
    """A generated-solver cache of this run's own: shared by the suite's workers (the run's base directory, which
    each worker's lies in), so a pattern one worker compiled the other loads (the cache takes concurrent builders);
    never a previous run's."""
    base = tmp_path_factory.getbasetemp()
    root = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "qocogen-shared"
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("TUBEKIT_QOCOGEN_CACHE", str(root))
        yield


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")


@pytest.mark.slow
def test_the_generated_solver_built_once_answers_as_clarabel_does_at_each_tolerance_and_in_the_certified_run(scenario):
    """One test, so the suite's workers never both build the paper's pattern (a build takes a core for about 20 s;
    a second builder would wait on the key's lock):

    * every subproblem of 1 s of the certified run (its periods' solves), solved by each backend: no failure, the
      plan's inputs within 1e-3 of Clarabel's and the objective within 1e-5 relative (QOCO's defaults, 1e-7, against
      the real-time Clarabel's 1e-6);
    * the tolerance study on the same problems at the default and two looser tolerances: the default is its own
      reference (no difference), every setting solves every problem, and the loosest needs no more iterations than
      the default;
    * the certified run of 2 s on the generated solver keeps its promises, its tracking as Clarabel's."""
    problems, inputs = STUDY.record(scenario, 1.0)
    assert len(problems) >= 10 and inputs.size == 3 * 8
    rows = STUDY.compare(problems, inputs, ("clarabel", "qocogen"))
    assert rows["clarabel"]["max_input_diff"] == 0.0
    gen = rows["qocogen"]
    assert (gen["failed"], gen["inaccurate"]) == (0, 0)
    assert gen["max_input_diff"] < 1e-3 and gen["max_objective_gap"] < 1e-5

    rows = STUDY.qocogen_tolerances(problems, inputs, (1e-6, 1e-4))
    assert list(rows) == ["1e-07 (default)", "1e-06", "0.0001"]
    assert rows["1e-07 (default)"]["max_input_diff"] == 0.0
    for row in rows.values():
        assert row["failed"] == 0 and len(row["iterations"]) == len(problems)
    assert sum(rows["0.0001"]["iterations"]) <= sum(rows["1e-07 (default)"]["iterations"])
    assert 0.0 < rows["0.0001"]["max_input_diff"] < 0.1

    loop = STUDY.closed_loop(scenario, 2.0, ("clarabel", "qocogen"))
    assert loop["qocogen"]["broken"] == [] == loop["clarabel"]["broken"]
    assert loop["qocogen"]["tracking_rmse"] == pytest.approx(loop["clarabel"]["tracking_rmse"], abs=1e-3)
    assert loop["qocogen"]["backup_s"] == 0.0
