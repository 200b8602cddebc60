"""The README's test command installs everything the suite needs, and CI installs nothing more (issue 35).

``pip install -e ".[test]" && pytest`` (the Quick start) must run the whole suite on a fresh machine: every
third-party module a test imports (at any level, or through ``pytest.importorskip``) comes from the package's
dependencies or its ``test`` extra. ``.ci/run`` runs that command verbatim and installs nothing else
(beyond upgrading pip), so a missing install step fails CI instead of hiding behind a green run.
"""

from __future__ import annotations

import ast
import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
CI_RUN = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
#: Import names whose distribution has another name (or comes with one that is listed: pillow with matplotlib).
DISTRIBUTION_OF = {"flint": "python-flint", "distributed": "dask", "PIL": "matplotlib"}
#: Folders whose modules the tests import as local code (not from a registry).
LOCAL_FOLDERS = (ROOT, ROOT / "tests", ROOT / "tutorials", ROOT / "benchmarks", ROOT / "docs")


def _name(requirement: str) -> str:
    """``"dask[distributed]>=2024.1"`` -> ``"dask"`` (PEP 503 normalised)."""
    return re.sub(r"[-_.]+", "-", re.split(r"[\[<>=!~; ]", requirement, maxsplit=1)[0]).lower()


def _imported_modules() -> dict[str, str]:
    """Top-level module imported by the tests -> one test file importing it (imports and importorskip)."""
    found: dict[str, str] = {}
    for path in sorted((ROOT / "tests").glob("*.py")):
        try:
            tree = ast.parse(path.read_text(encoding="utf-8"))
        except FileNotFoundError:  # renamed while listing
            continue
        for node in ast.walk(tree):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            elif (isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "importorskip"
                  and node.args and isinstance(node.args[0], ast.Constant)):
                names = [str(node.args[0].value)]
            for name in names:
                found.setdefault(name.split(".")[0], path.name)
    return found


def _is_local(module: str) -> bool:
    return any((folder / f"{module}.py").is_file() or (folder / module).is_dir() for folder in LOCAL_FOLDERS)


def test_ci_installs_nothing_beyond_the_readme_command():
    """The only ``pip install`` of ``.ci/run`` upgrades pip; the test command comes from the README."""
    installs = [line.strip() for line in CI_RUN.splitlines()
                if "pip install" in line and not line.lstrip().startswith("#")]
    assert installs == ["python -m pip install --quiet --upgrade pip"], installs
    assert "README.md" in CI_RUN and 'eval "$cmd"' in CI_RUN


def test_the_test_extra_holds_the_optional_peers():
    """casadi (the IPOPT peer tests), dask and pyarrow (campaigns), piqp: in the ``test`` extra itself."""
    extra = {_name(r) for r in PYPROJECT["project"]["optional-dependencies"]["test"]}
    assert {"casadi", "dask", "pyarrow", "piqp", "pytest"} <= extra


def test_every_module_the_tests_import_is_installed_by_the_test_command():
    """Each third-party module a test imports comes from a dependency or the ``test`` extra."""
    project = PYPROJECT["project"]
    installed = {_name(r) for r in [*project["dependencies"], *project["optional-dependencies"]["test"]]}
    missing = {module: where for module, where in _imported_modules().items()
               if module not in sys.stdlib_module_names and not _is_local(module)
               and _name(DISTRIBUTION_OF.get(module, module)) not in installed}
    assert not missing, f"imported by the tests, installed by neither the dependencies nor [test]: {missing}"


def test_the_plugins_the_suite_is_configured_with_are_in_the_test_extra():
    """``addopts`` runs the suite on every core (``-n auto``: pytest-xdist), so the ``test`` extra installs it."""
    addopts = PYPROJECT["tool"]["pytest"]["ini_options"]["addopts"].split()
    extra = {_name(r) for r in PYPROJECT["project"]["optional-dependencies"]["test"]}
    assert "-n" in addopts and "pytest-xdist" in extra
