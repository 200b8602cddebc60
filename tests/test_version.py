"""The one version string (:mod:`tubekit.version`): both packages, the installed metadata and the
CLI report the same version, and the build reads it from that module only."""

from __future__ import annotations

import importlib.metadata
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import tubekit
import verify
from tubekit.version import __version__

ROOT = Path(__file__).resolve().parents[1]
#: A release version in the public form of PEP 440 (e.g. 0.1.0, 1.2.0rc1, 2.0.post1).
PEP440 = re.compile(r"^\d+(\.\d+)*((a|b|rc)\d+)?(\.post\d+)?(\.dev\d+)?$")


def test_both_packages_and_the_installed_metadata_agree():
    assert tubekit.__version__ == verify.__version__ == importlib.metadata.version("tubekit")
    assert tubekit.__version__ is __version__  # one object, imported from one place


def test_the_version_is_a_public_pep440_version():
    assert PEP440.match(__version__), __version__
    assert not PEP440.match("0.1.0-local"), "the pattern itself must reject a non-PEP 440 string"


def test_the_build_reads_the_version_from_tubekit_version():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert project["project"]["dynamic"] == ["version"]
    assert "version" not in {k for k in project["project"] if k != "dynamic"}
    assert project["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "tubekit.version.__version__"}


def test_the_version_is_exported_by_both_packages():
    assert "__version__" in tubekit.__all__ and "__version__" in verify.__all__


def test_the_cli_prints_the_same_version():
    run = subprocess.run([sys.executable, "-m", "tubekit", "--version"], cwd=ROOT, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == f"tubekit {__version__}"
