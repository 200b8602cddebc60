"""The layering rules of issue 10, checked on the source: core <- solver and plant <- verify <- app.

Every module of ``tubekit/`` and ``verify/`` is parsed with :mod:`ast` (no import
is executed); its imports are every ``import`` / ``from ... import`` statement
anywhere in the file (module level, inside functions, under ``if TYPE_CHECKING``),
every ``importlib.import_module("...")`` / ``__import__("...")`` call with a
literal name, and every string literal that is exactly the dotted name of a
submodule (a registry such as ``{"falsify": "verify.falsify.one_period"}`` imported by name
later). See ``docs/architecture.md``.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("tubekit", "verify")
APP = "tubekit.app"
GUI_AND_CLI = ("argparse", "matplotlib", "mpl_toolkits")
MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 100


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


def _is_app(name: str) -> bool:
    return _within(name, APP)


def _is_core(name: str) -> bool:
    return _within(name, "tubekit") and not _is_app(name)


def _offenders(rule) -> list[str]:
    """``path:line imports target`` for every import for which ``rule(module, target)`` is true.

    One entry a line: the shortest offending target of the statement (``matplotlib.figure``,
    not also ``matplotlib.figure.Figure``).
    """
    first: dict[tuple[str, int], str] = {}
    for m in modules().values():
        for imp in imports(m):
            key = (m.rel, imp.line)
            if rule(m.name, imp.target) and (key not in first or len(imp.target) < len(first[key])):
                first[key] = imp.target
    return [f"{rel}:{line} imports {target}" for (rel, line), target in sorted(first.items())]


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
    assert {"tubekit", "verify", "tubekit.scenario", "verify.region"} <= names, sorted(names)


def test_argparse_and_matplotlib_only_in_the_app_layer():
    offenders = _offenders(lambda mod, target: not _is_app(mod)
                           and any(_within(target, lib) for lib in GUI_AND_CLI))
    assert not offenders, _report(f"{', '.join(GUI_AND_CLI)} may be imported only under tubekit/app/", offenders)


def test_the_core_never_imports_verify():
    offenders = _offenders(lambda mod, target: _is_core(mod) and _within(target, "verify"))
    assert not offenders, _report("the tubekit core (tubekit/ outside tubekit/app/) must not import verify",
                                  offenders)


def test_verify_never_imports_the_app_layer():
    offenders = _offenders(lambda mod, target: _within(mod, "verify") and _is_app(target))
    assert not offenders, _report("verify must not import tubekit.app", offenders)


def test_no_import_cycles():
    cycles = find_cycles(import_graph())
    assert not cycles, _report("import cycles between modules", [" -> ".join(c) for c in cycles])


def test_no_module_over_the_line_limit():
    offenders = sorted(f"{m.rel}: {m.lines} lines" for m in modules().values() if m.lines > MAX_MODULE_LINES)
    assert not offenders, _report(f"modules over {MAX_MODULE_LINES} lines", offenders)


def test_no_function_over_the_hard_line_limit():
    offenders = []
    for m in modules().values():
        for node in ast.walk(m.tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    offenders.append(f"{m.rel}:{node.lineno} {node.name}: {length} lines")
    assert not offenders, _report(f"functions over {MAX_FUNCTION_LINES} lines (hard limit)", sorted(offenders))


def test_importing_the_packages_loads_no_matplotlib():
    code = "import sys, tubekit, verify; print('matplotlib' in sys.modules)"
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"`python -c {code!r}` failed:\n{run.stderr}"
    assert run.stdout.strip() == "False", (f"`import tubekit, verify` loads matplotlib (printed "
                                           f"{run.stdout.strip()!r}); plotting belongs in tubekit/app/")


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
