"""The layering rules of ``docs/architecture.md``, checked on the source as package-prefix rules.

The layers, from the ground up: ``tubekit.exceptions`` / ``validation`` / ``version``, then
``tubekit.model``, then the configuration (``scenario``, ``tightening``, ``checks``,
``design_key``), then the run (``tubekit.plant`` and ``tubekit.fhocp``, then ``tubekit.loop``);
``verify`` needs the model and the configuration, and only ``verify.falsify`` runs the loop;
``tubekit.app`` (with the ``python -m tubekit`` shim) sits on top and is the only layer that
parses arguments or joins tubekit and verify; it and ``tubekit.plotting`` (the figures of a run, beside the
solver and the plant: it imports only the configuration, the model and the ground) are the only code that
imports matplotlib.

Every module of ``tubekit/`` and ``verify/`` is parsed with :mod:`ast` (no import
is executed); its imports are every ``import`` / ``from ... import`` statement
anywhere in the file (module level, inside functions, under ``if TYPE_CHECKING``),
every ``importlib.import_module("...")`` / ``__import__("...")`` call with a
literal name, and every string literal that is exactly the dotted name of a
submodule (a registry such as ``{"falsify": "verify.falsify.one_period"}`` imported by name
later). A failure lists every offender as ``path:line -> imported name``.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Callable, Iterable

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("tubekit", "verify")
APP = "tubekit.app"
#: The app layer: tubekit.app and the ``python -m tubekit`` shim that hands over to its CLI.
APP_LAYER = (APP, "tubekit.__main__")
CLI = ("argparse",)
GUI = ("matplotlib", "mpl_toolkits")
GUI_AND_CLI = (*CLI, *GUI)
#: The plotting role: the only code outside the app layer that imports matplotlib; it draws a run from its
#: columns, so it imports none of these (``SimulationResult.plot()`` imports it lazily: no cycle).
PLOTTING = "tubekit.plotting"
PLOTTING_MAY_NOT_IMPORT = ("tubekit.loop", "tubekit.fhocp", "tubekit.plant", APP, "verify")
MODEL = "tubekit.model"
MODEL_MAY_IMPORT = (MODEL, "tubekit.exceptions", "tubekit.validation", "tubekit.version")
CONFIGURATION = ("tubekit.settings", "tubekit.scenario", "tubekit.tightening", "tubekit.checks", "tubekit.design_inputs",
                 "tubekit.tiers")
RUN_AND_APP = ("tubekit.plant", "tubekit.fhocp", "tubekit.loop", APP)
PLANT_AND_SOLVER = ("tubekit.plant", "tubekit.fhocp")
LOOP = "tubekit.loop"
THE_RUN = ("tubekit.plant", "tubekit.fhocp", LOOP)
FALSIFIERS = "verify.falsify"
#: verify's roles, bottom up: the Arb kernel; the theorem (with the backup's proof and the dynamic vehicle's
#: bound); the paper's Lemma 1 (a reference beside the theorem); the certificate artefact; re-checks, studies
#: and tools; the falsifiers (the only verify that runs the loop).
VERIFY_KERNEL = "verify.kernel"
VERIFY_THEOREM = ("verify.theorem", "verify.backup", "verify.vehicle")
VERIFY_REFERENCE = "verify.lemma1"
VERIFY_CERTIFICATE = "verify.certificate"
VERIFY_STUDIES = "verify.studies"
VERIFY_ROLES = (VERIFY_KERNEL, *VERIFY_THEOREM, VERIFY_REFERENCE, VERIFY_CERTIFICATE, VERIFY_STUDIES, FALSIFIERS)
MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80


@dataclass(frozen=True)
class Import:
    """One imported name: ``target`` is dotted (``pkg.mod`` or ``pkg.mod.attr``), ``line`` its line number."""

    target: str
    line: int


@dataclass(frozen=True)
class Module:
    """A parsed source module of the two packages."""

    name: str
    path: Path
    is_package: bool
    tree: ast.Module
    lines: int

    @property
    def rel(self) -> str:
        """Path relative to the repository root."""
        return self.path.relative_to(ROOT).as_posix()


def _module_name(path: Path) -> tuple[str, bool]:
    """Dotted name of a source file and whether it is a package ``__init__``."""
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    is_package = parts[-1] == "__init__"
    if is_package:
        parts = parts[:-1]
    return ".".join(parts), is_package


@lru_cache(maxsize=1)
def modules() -> dict[str, Module]:
    """Every ``*.py`` module under ``tubekit/`` and ``verify/``, by dotted name."""
    out: dict[str, Module] = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            text = path.read_text(encoding="utf-8")
            name, is_package = _module_name(path)
            out[name] = Module(name=name, path=path, is_package=is_package,
                               tree=ast.parse(text, filename=str(path)), lines=len(text.splitlines()))
    return out


def _resolve_relative(module: Module, level: int, target: str | None) -> str:
    """Absolute name of ``from <level dots><target> import ...`` written in ``module``."""
    base = module.name.split(".")
    if not module.is_package:
        base = base[:-1]
    if level > 1:
        base = base[: len(base) - (level - 1)]
    return ".".join(base + ([target] if target else []))


def _literal_import_call(node: ast.Call) -> str | None:
    """The module name of ``importlib.import_module("x")`` / ``__import__("x")``, else None."""
    func = node.func
    name = func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else None
    if name not in ("import_module", "__import__") or not node.args:
        return None
    first = node.args[0]
    return first.value if isinstance(first, ast.Constant) and isinstance(first.value, str) else None


def imports(module: Module) -> list[Import]:
    """Every name ``module`` imports, anywhere in the file (see the module doc)."""
    found: list[Import] = []
    for node in ast.walk(module.tree):
        if isinstance(node, ast.Import):
            found.extend(Import(alias.name, node.lineno) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = _resolve_relative(module, node.level, node.module) if node.level else node.module or ""
            names = [f"{base}.{alias.name}" for alias in node.names if alias.name != "*"]
            if not names or not all(name in modules() for name in names):
                found.append(Import(base, node.lineno))  # names from the module itself, not only submodules
            found.extend(Import(name, node.lineno) for name in names)
        elif isinstance(node, ast.Call) and (literal := _literal_import_call(node)):
            found.append(Import(literal, node.lineno))
        elif isinstance(node, ast.Constant) and _names_a_submodule(node.value):
            found.append(Import(node.value, node.lineno))  # a registry entry imported by name later
    return found


def _names_a_submodule(value: object) -> bool:
    """True for a string that is exactly the dotted name of a submodule, e.g. ``"verify.falsify.one_period"``."""
    return isinstance(value, str) and "." in value and value in modules()


def _within(name: str, prefix: str) -> bool:
    """True if dotted ``name`` is ``prefix`` or inside it."""
    return name == prefix or name.startswith(prefix + ".")


def _within_any(name: str, prefixes: tuple[str, ...]) -> bool:
    """True if dotted ``name`` is inside one of ``prefixes``."""
    return any(_within(name, prefix) for prefix in prefixes)


def _is_app(name: str) -> bool:
    return _within_any(name, APP_LAYER)


def _is_core(name: str) -> bool:
    return _within(name, "tubekit") and not _is_app(name)


def _is_first_party(name: str) -> bool:
    return _within_any(name, PACKAGES)


def _offenders(rule: Callable[[str, str], bool], among: Iterable[Module] | None = None) -> list[str]:
    """``path:line -> target`` for every import for which ``rule(module, target)`` is true.

    ``among`` defaults to every module of the two packages (the checker's self-tests pass fakes).
    One entry a line: the shortest offending target of the statement (``matplotlib.figure``,
    not also ``matplotlib.figure.Figure``).
    """
    first: dict[tuple[str, int], str] = {}
    for m in modules().values() if among is None else among:
        for imp in imports(m):
            key = (m.rel, imp.line)
            if rule(m.name, imp.target) and (key not in first or len(imp.target) < len(first[key])):
                first[key] = imp.target
    return [f"{rel}:{line} -> {target}" for (rel, line), target in sorted(first.items())]


# --------------------------------------------------------------------------- the rules as predicates
# Each rule is ``rule(importing module, imported target) -> True when the import breaks it``; the
# tests below apply it to the real tree and the checker's self-tests to fake modules.
def model_reaches_above(mod: str, target: str) -> bool:
    """tubekit.model imports, of the two packages, only itself, exceptions, validation and version."""
    return _within(mod, MODEL) and _is_first_party(target) and not _within_any(target, MODEL_MAY_IMPORT)


def configuration_reaches_the_run(mod: str, target: str) -> bool:
    """scenario / tightening / checks / design_key import no plant, fhocp, loop or app."""
    return _within_any(mod, CONFIGURATION) and _within_any(target, RUN_AND_APP)


def plant_or_solver_reaches_the_loop(mod: str, target: str) -> bool:
    """tubekit.plant and tubekit.fhocp import no tubekit.loop."""
    return _within_any(mod, PLANT_AND_SOLVER) and _within(target, LOOP)


def imports_the_app_layer(mod: str, target: str) -> bool:
    """Nothing outside the app layer (tubekit.app and the ``python -m tubekit`` shim) imports tubekit.app."""
    return not _is_app(mod) and _within(target, APP)


def core_imports_verify(mod: str, target: str) -> bool:
    """The tubekit core (tubekit outside the app layer) imports no verify."""
    return _is_core(mod) and _within(target, "verify")


def verify_runs_the_loop(mod: str, target: str) -> bool:
    """verify outside verify.falsify imports no tubekit.plant, tubekit.fhocp, tubekit.loop."""
    return _within(mod, "verify") and not _within(mod, FALSIFIERS) and _within_any(target, THE_RUN)


def verify_kernel_reaches_up(mod: str, target: str) -> bool:
    """verify.kernel imports no other part of verify (not even the package root)."""
    return _within(mod, VERIFY_KERNEL) and _within(target, "verify") and not _within(target, VERIFY_KERNEL)


def verify_theorem_reaches_up(mod: str, target: str) -> bool:
    """The theorem (verify.theorem, verify.backup, verify.vehicle) imports only the kernel and itself of verify."""
    return (_within_any(mod, VERIFY_THEOREM) and _within(target, "verify")
            and not _within_any(target, (VERIFY_KERNEL, *VERIFY_THEOREM)))


def verify_reference_reaches_up(mod: str, target: str) -> bool:
    """verify.lemma1 (the paper's Lemma 1, a reference) imports only the kernel and itself of verify."""
    return (_within(mod, VERIFY_REFERENCE) and _within(target, "verify")
            and not _within_any(target, (VERIFY_KERNEL, VERIFY_REFERENCE)))


def verify_certificate_reaches_up(mod: str, target: str) -> bool:
    """The certificate artefact imports no re-check, study or falsifier."""
    return _within(mod, VERIFY_CERTIFICATE) and _within_any(target, (VERIFY_STUDIES, FALSIFIERS))


def verify_studies_reach_the_falsifiers(mod: str, target: str) -> bool:
    """Re-checks and studies import no falsifier."""
    return _within(mod, VERIFY_STUDIES) and _within(target, FALSIFIERS)


def gui_or_cli_outside_the_app(mod: str, target: str) -> bool:
    """argparse is imported only in the app layer; matplotlib and mpl_toolkits only there and in tubekit.plotting."""
    if _is_app(mod):
        return False
    return _within_any(target, CLI) or (_within_any(target, GUI) and not _within(mod, PLOTTING))


def plotting_reaches_the_run(mod: str, target: str) -> bool:
    """tubekit.plotting imports no tubekit.loop, tubekit.fhocp, tubekit.plant, tubekit.app or verify."""
    return _within(mod, PLOTTING) and _within_any(target, PLOTTING_MAY_NOT_IMPORT)


def _owning_module(target: str) -> str | None:
    """The longest dotted prefix of ``target`` that is a module of the two packages."""
    parts = target.split(".")
    for k in range(len(parts), 0, -1):
        candidate = ".".join(parts[:k])
        if candidate in modules():
            return candidate
    return None


def import_graph() -> dict[str, set[str]]:
    """Module -> the modules of the two packages it imports (self-imports dropped)."""
    graph: dict[str, set[str]] = {name: set() for name in modules()}
    for name, module in modules().items():
        for imp in imports(module):
            owner = _owning_module(imp.target)
            if owner is not None and owner != name:
                graph[name].add(owner)
    return graph


def find_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Every cycle closed by a back edge of a depth-first search, as ``[a, b, ..., a]``, each once."""
    state: dict[str, int] = {}  # 1 on the DFS stack, 2 finished
    stack: list[str] = []
    cycles: dict[tuple[str, ...], list[str]] = {}

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for succ in sorted(graph.get(node, ())):
            if state.get(succ) == 1:
                cycle = stack[stack.index(succ):]
                start = cycle.index(min(cycle))
                key = tuple(cycle[start:] + cycle[:start])
                cycles.setdefault(key, list(key) + [key[0]])
            elif succ not in state:
                visit(succ)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)
    return list(cycles.values())


def _report(rule: str, offenders: list[str]) -> str:
    return f"{rule} ({len(offenders)} offending):\n  " + "\n  ".join(offenders)


# --------------------------------------------------------------------------- the rules
def test_the_packages_are_found():
    """Guard: the walk sees both packages (an empty walk would pass every rule)."""
    names = set(modules())
    assert {"tubekit", "verify", "tubekit.scenario", "verify.kernel.region", "tubekit.model.errors",
            "tubekit.loop.result", "tubekit.app.cli", "verify.falsify.closed_loop"} <= names, sorted(names)


def test_the_model_imports_nothing_above_it():
    offenders = _offenders(model_reaches_above)
    assert not offenders, _report(f"tubekit.model may import only {', '.join(MODEL_MAY_IMPORT)}", offenders)


def test_the_configuration_imports_no_plant_solver_loop_or_app():
    offenders = _offenders(configuration_reaches_the_run)
    assert not offenders, _report(f"{', '.join(CONFIGURATION)} must not import {', '.join(RUN_AND_APP)}",
                                  offenders)


def test_plant_and_fhocp_import_no_loop():
    offenders = _offenders(plant_or_solver_reaches_the_loop)
    assert not offenders, _report(f"{' and '.join(PLANT_AND_SOLVER)} must not import {LOOP}", offenders)


def test_nothing_outside_the_app_layer_imports_it():
    offenders = _offenders(imports_the_app_layer)
    assert not offenders, _report(f"only {' and '.join(APP_LAYER)} may import {APP} (lazy imports included)",
                                  offenders)


def test_the_core_never_imports_verify():
    offenders = _offenders(core_imports_verify)
    assert not offenders, _report("the tubekit core (tubekit/ outside tubekit/app/) must not import verify",
                                  offenders)


def test_verify_runs_the_loop_only_in_the_falsifiers():
    offenders = _offenders(verify_runs_the_loop)
    assert not offenders, _report(f"verify outside {FALSIFIERS} must not import {', '.join(THE_RUN)}", offenders)


def test_every_verify_module_belongs_to_a_role():
    """verify has no flat module besides its package root: each lives in one role subpackage."""
    flat = sorted(m.rel for m in modules().values()
                  if _within(m.name, "verify") and m.name != "verify" and not _within_any(m.name, VERIFY_ROLES))
    assert not flat, _report("verify modules outside a role subpackage", flat)


@pytest.mark.parametrize("rule", [verify_kernel_reaches_up, verify_theorem_reaches_up, verify_reference_reaches_up,
                                  verify_certificate_reaches_up, verify_studies_reach_the_falsifiers],
                         ids=lambda rule: rule.__name__)
def test_verify_roles_import_only_downwards(rule):
    """Each verify role imports only the roles under it (kernel < theorem, reference < certificate < studies)."""
    offenders = _offenders(rule)
    assert not offenders, _report(rule.__doc__, offenders)


def test_argparse_only_in_the_app_layer_and_matplotlib_there_and_in_plotting():
    offenders = _offenders(gui_or_cli_outside_the_app)
    assert not offenders, _report(f"{', '.join(CLI)} may be imported only under tubekit/app/, {', '.join(GUI)} "
                                  f"only there and under tubekit/plotting/", offenders)


def test_plotting_imports_only_the_configuration_and_the_model():
    offenders = _offenders(plotting_reaches_the_run)
    assert not offenders, _report(f"{PLOTTING} must not import {', '.join(PLOTTING_MAY_NOT_IMPORT)}", offenders)


def test_no_import_cycles():
    cycles = find_cycles(import_graph())
    assert not cycles, _report("import cycles between modules", [" -> ".join(c) for c in cycles])


def test_no_module_over_the_line_limit():
    offenders = sorted(f"{m.rel}: {m.lines} lines" for m in modules().values() if m.lines > MAX_MODULE_LINES)
    assert not offenders, _report(f"modules over {MAX_MODULE_LINES} lines", offenders)


def long_functions(among: Iterable[Module] | None = None) -> list[str]:
    """``path:line name: N lines`` for every function (methods and nested ones too) over the limit."""
    offenders = []
    for m in modules().values() if among is None else among:
        for node in ast.walk(m.tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    offenders.append(f"{m.rel}:{node.lineno} {node.name}: {length} lines")
    return sorted(offenders)


def test_no_function_over_the_line_limit():
    offenders = long_functions()
    assert not offenders, _report(f"functions over {MAX_FUNCTION_LINES} lines", offenders)


def test_importing_the_packages_loads_no_matplotlib_and_no_sympy():
    code = "import sys, tubekit, verify; print(sorted(m for m in ('matplotlib', 'sympy') if m in sys.modules))"
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"`python -c {code!r}` failed:\n{run.stderr}"
    assert run.stdout.strip() == "[]", (f"`import tubekit, verify` loads {run.stdout.strip()}: plotting belongs "
                                        f"in tubekit/app/ and tubekit/plotting/ (imported on use), the sympy "
                                        f"derivation is imported only on use")


# --------------------------------------------------------------------------- the checker itself
def test_the_cycle_finder_reports_a_cycle_once_and_ignores_a_diamond():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"b", "d"}}
    assert find_cycles(graph) == [["a", "b", "c", "a"]]
    assert find_cycles({"a": {"b", "c"}, "b": {"d"}, "c": {"d"}, "d": set()}) == []


def test_relative_imports_resolve_inside_packages():
    tree = ast.parse("from . import x\nfrom ..core import y\nimport argparse\n"
                     "def f():\n    from .sub import z\n    importlib.import_module('verify.falsify.one_period')\n")
    fake = Module(name="tubekit.app.cli", path=ROOT / "tubekit/app/cli.py", is_package=False, tree=tree, lines=6)
    targets = {imp.target for imp in imports(fake)}
    assert {"tubekit.app", "tubekit.app.x", "tubekit.core.y", "argparse", "tubekit.app.sub.z",
            "verify.falsify.one_period"} <= targets
    # importing submodules from a package is an edge to the submodules only, not to the package __init__
    sub = Module(name="tubekit.app.cli", path=ROOT / "tubekit/app/cli.py", is_package=False,
                 tree=ast.parse("from .. import scenario, model\n"), lines=1)
    assert {imp.target for imp in imports(sub)} == {"tubekit.scenario", "tubekit.model"}
    pkg = Module(name="tubekit.fhocp", path=ROOT / "tubekit/fhocp/__init__.py", is_package=True,
                 tree=ast.parse("from .result import R\n"), lines=1)
    assert {imp.target for imp in imports(pkg)} == {"tubekit.fhocp.result", "tubekit.fhocp.result.R"}


def _fake(name: str, source: str, is_package: bool = False) -> Module:
    """A module that is not on disk, parsed from ``source``, for the checker's self-tests."""
    rel = name.replace(".", "/") + ("/__init__.py" if is_package else ".py")
    return Module(name=name, path=ROOT / rel, is_package=is_package, tree=ast.parse(source),
                  lines=len(source.splitlines()))


def test_the_app_rule_catches_a_lazy_import_from_the_loop():
    """``SimulationResult.plot()`` importing ``tubekit.app.plots`` inside the method (as it did) breaks the rule."""
    lazy = _fake("tubekit.loop.result", "class SimulationResult:\n    def plot(self):\n"
                 "        from tubekit.app.plots import plot_run\n        return plot_run(self)\n")
    relative = _fake("tubekit.loop.result", "def plot(run):\n    from ..app import plots\n")
    by_name = _fake("verify.certificate.report", "import importlib\n\ndef f():\n"
                    "    return importlib.import_module('tubekit.app.plots')\n")
    assert _offenders(imports_the_app_layer, among=[lazy]) == ["tubekit/loop/result.py:3 -> tubekit.app.plots"]
    assert _offenders(imports_the_app_layer, among=[relative]) == ["tubekit/loop/result.py:2 -> tubekit.app.plots"]
    assert _offenders(imports_the_app_layer, among=[by_name]) == ["verify/certificate/report.py:4 -> tubekit.app.plots"]
    inside = _fake("tubekit.app.study", "from tubekit.app.plots import plot_run\nfrom . import output\n")
    shim = _fake("tubekit.__main__", "def run():\n    from tubekit.app.cli import main\n")
    assert _offenders(imports_the_app_layer, among=[inside, shim]) == []


def test_the_layer_rules_flag_only_what_they_name():
    model = _fake("tubekit.model.kinematics", "from tubekit.validation import positive\n"
                  "from tubekit.model import errors\nfrom .. import scenario\nimport tubekit\n"
                  "def f():\n    import verify.kernel.region\n")
    assert _offenders(model_reaches_above, among=[model]) == [
        "tubekit/model/kinematics.py:3 -> tubekit.scenario", "tubekit/model/kinematics.py:4 -> tubekit",
        "tubekit/model/kinematics.py:6 -> verify.kernel.region"]
    config = _fake("tubekit.design_inputs", "from tubekit.model import errors\nfrom tubekit.fhocp.result import Status\n")
    assert _offenders(configuration_reaches_the_run, among=[config]) == [
        "tubekit/design_inputs.py:2 -> tubekit.fhocp.result"]
    solver = _fake("tubekit.fhocp.scp", "from tubekit.plant import base\nfrom tubekit.loop.sensing import x\n")
    assert _offenders(plant_or_solver_reaches_the_loop, among=[solver]) == [
        "tubekit/fhocp/scp.py:2 -> tubekit.loop.sensing"]
    checker = _fake("verify.theorem.design", "from tubekit.scenario import Scenario\nimport tubekit.loop.plan_check\n")
    falsifier = _fake("verify.falsify.closed_loop", "import tubekit.loop.plan_check\n")
    assert _offenders(verify_runs_the_loop, among=[checker, falsifier]) == [
        "verify/theorem/design.py:2 -> tubekit.loop.plan_check"]
    kernel = _fake("verify.kernel.region", "from verify.kernel import intervals\nfrom verify.theorem import design\n")
    theorem = _fake("verify.backup.proof", "from verify.theorem.design import Condition\n"
                    "from verify.certificate.record import CertificateRecord\n")
    artefact = _fake("verify.certificate.report", "from verify.theorem import tiers\nfrom verify.studies import recheck\n")
    assert _offenders(verify_kernel_reaches_up, among=[kernel]) == ["verify/kernel/region.py:2 -> verify.theorem.design"]
    assert _offenders(verify_theorem_reaches_up, among=[theorem]) == [
        "verify/backup/proof.py:2 -> verify.certificate.record"]
    assert _offenders(verify_certificate_reaches_up, among=[artefact]) == [
        "verify/certificate/report.py:2 -> verify.studies.recheck"]
    core = _fake("tubekit.loop.promises", "def f():\n    import matplotlib.pyplot as plt\n    import verify\n")
    assert _offenders(gui_or_cli_outside_the_app, among=[core]) == ["tubekit/loop/promises.py:2 -> matplotlib.pyplot"]
    assert _offenders(core_imports_verify, among=[core]) == ["tubekit/loop/promises.py:3 -> verify"]
    plotting = _fake("tubekit.plotting.top_view", "import argparse\nfrom matplotlib.figure import Figure\n"
                     "from tubekit.scenario import Scenario\nfrom tubekit.model.errors import numeric\n"
                     "from tubekit.loop.result import SimulationResult\nfrom tubekit.app.plots import plot_all\n"
                     "def f():\n    import tubekit.plant.dynamic\n    import verify\n")
    assert _offenders(gui_or_cli_outside_the_app, among=[plotting]) == ["tubekit/plotting/top_view.py:1 -> argparse"]
    assert _offenders(plotting_reaches_the_run, among=[plotting]) == [
        "tubekit/plotting/top_view.py:5 -> tubekit.loop.result", "tubekit/plotting/top_view.py:6 -> tubekit.app.plots",
        "tubekit/plotting/top_view.py:8 -> tubekit.plant.dynamic", "tubekit/plotting/top_view.py:9 -> verify"]


def test_the_function_limit_counts_methods_and_stops_at_the_limit():
    assert (MAX_MODULE_LINES, MAX_FUNCTION_LINES) == (500, 80), "the house rules' limits (issue 19)"
    at_limit = "def f():\n" + "    x = 1\n" * (MAX_FUNCTION_LINES - 1)
    over = "class C:\n    def g(self):\n" + "        x = 1\n" * MAX_FUNCTION_LINES
    fake = [_fake("tubekit.a", at_limit), _fake("tubekit.b", over)]
    assert long_functions(among=fake) == [f"tubekit/b.py:2 g: {MAX_FUNCTION_LINES + 1} lines"]
