"""Build executed Jupyter notebooks from the percent-format tutorials (the `.py` files are the source).

    python docs/regenerate.py                      # what to run: notebooks, figures and the sidecar together
    python tutorials/build_notebooks.py            # the notebooks only, full sizes, into tutorials/notebooks/
    TUBEKIT_QUICK=1 python tutorials/build_notebooks.py --out /tmp/nb   # reduced sizes

Each tutorial is converted with jupytext and executed with nbclient in a fresh kernel, so a
student opening a notebook sees the prose, the printed results and the figures inline. A notebook
built by ``docs/regenerate.py`` carries the code's fingerprint in ``metadata["tubekit"]`` (the numbers
``tests/test_regenerate.py`` recomputes); one built here alone carries none, and the tests call it stale.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import jupytext
import nbformat
from jupyter_client import KernelManager
from nbclient import NotebookClient

HERE = Path(__file__).resolve().parent


def relative_paths(nb, root: Path = HERE.parent) -> None:
    """Print paths relative to the repository in every text output (a notebook carries no machine's paths)."""
    prefix = str(root) + "/"
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            if "text" in out:
                out["text"] = out["text"].replace(prefix, "")
            data = out.get("data", {})
            if "text/plain" in data:
                data["text/plain"] = data["text/plain"].replace(prefix, "")


def build(tutorial: Path, out_dir: Path, figures: Path, timeout_s: int = 900, stamp: dict | None = None) -> Path:
    """Execute ``tutorial`` as a notebook; write ``out_dir/<name>.ipynb``; return its path.

    ``stamp`` (optional, JSON-ready) is stored as ``metadata["tubekit"]`` (the fingerprint of the code).
    """
    nb = jupytext.read(tutorial)
    os.environ.setdefault("TUBEKIT_FIGURES", str(figures))
    figures.mkdir(parents=True, exist_ok=True)
    km = KernelManager(kernel_name="python3", ip="127.0.0.1")  # the kernel listens on loopback only
    NotebookClient(nb, km=km, timeout=timeout_s, kernel_name="python3",
                   resources={"metadata": {"path": str(figures)}}).execute()
    relative_paths(nb)
    if stamp is not None:
        nb.metadata["tubekit"] = stamp
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / f"{tutorial.stem}.ipynb"
    tmp = out_dir / f".{tutorial.stem}.partial.ipynb"
    nbformat.write(nb, str(tmp))
    os.replace(tmp, target)
    return target


def tutorials() -> list[Path]:
    """The tutorial scripts, in order (``NN_name.py``)."""
    return sorted(HERE.glob("[0-9][0-9]_*.py"))


def build_all(stamp: dict | None = None, out_dir: Path = HERE / "notebooks") -> list[str]:
    """Build every tutorial at full size (``TUBEKIT_QUICK`` unset); return the notebooks' repository paths."""
    os.environ.pop("TUBEKIT_QUICK", None)
    written = []
    for f in tutorials():
        print(f"building {f.stem} ...", flush=True)
        written.append(build(f, out_dir, HERE / "figures", stamp=stamp).relative_to(HERE.parent).as_posix())
    return written


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE / "notebooks", help="output directory")
    parser.add_argument("names", nargs="*", help="tutorial stems (default: all)")
    args = parser.parse_args()
    files = tutorials()
    if args.names:
        files = [f for f in files if f.stem in args.names]
    for f in files:
        print(f"building {f.stem} ...", flush=True)
        print(f"  wrote {build(f, args.out, HERE / 'figures')}")


if __name__ == "__main__":
    main()
