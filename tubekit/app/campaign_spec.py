"""The SPEC.toml of ``tubekit campaign``: parsing, validation and the deterministic plan of every run.

A spec names a base scenario, how many runs, one seed and what to sample::

    scenario = "paper_currents.toml"   # relative to the spec, or "paper"
    runs = 200
    seed = 7
    duration = 30.0                    # s, optional (default: the scenario's)

    [sample]                           # dotted scenario keys -> a distribution
    "disturbance.amplitude" = { uniform = [[0.05, 0.05, 0.05], [0.1, 0.1, 0.1]] }   # elementwise
    "disturbance.period" = { uniform = [8.0, 20.0] }
    "controller.law" = { choice = ["corrected"] }

    [falsify]                          # optional
    sequences = 2                      # random piecewise-constant disturbances per run

Run ``k`` gets its own seed, ``SeedSequence(seed).spawn(runs)[k]`` reduced to one integer
(:func:`run_seed`); its samples are drawn from ``default_rng([run_seed, 0])`` in the sorted order
of the keys, its disturbance sequences (worker side) from ``default_rng([run_seed, 1])``. Run ``k``
is therefore the same whatever ``runs`` is, whatever the worker, the order or the scheduler.
Every error is a :class:`~tubekit.exceptions.ConfigError` naming the spec field.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tubekit.checks import require_one_period
from tubekit.exceptions import ConfigError, TubekitError
from tubekit.scenario import Scenario, load_scenario, paper_scenario, read_toml, scenario_from_dict

__all__ = ["Distribution", "CampaignSpec", "RunPlan", "load_spec", "spec_from_dict", "run_seed",
           "certificate_key", "spec_from_stored", "require_dependencies", "NOT_CERTIFICATE_INPUTS", "SPEC_KEYS"]

#: Top-level keys of a spec.
SPEC_KEYS = ("scenario", "runs", "seed", "duration", "sample", "falsify")
#: Scenario keys ``verify.certify`` does not read (a test keeps this true): samples of these share a certificate.
NOT_CERTIFICATE_INPUTS = ("name", "duration", "disturbance.period")
#: Upper bound on ``runs`` (a typo guard; 10^6 run files is already a lot).
MAX_RUNS = 1_000_000


@dataclass(frozen=True)
class Distribution:
    """``uniform`` on [lo, hi] (elementwise for vectors) or ``choice`` among ``options``."""

    kind: str
    low: Any = None
    high: Any = None
    options: tuple = ()

    def draw(self, rng: np.random.Generator) -> Any:
        """One value: a float, a list of floats (vector uniform) or one of ``options``."""
        if self.kind == "choice":
            return self.options[int(rng.integers(len(self.options)))]
        value = rng.uniform(np.asarray(self.low, dtype=float), np.asarray(self.high, dtype=float))
        return value.tolist() if np.ndim(value) else float(value)

    def to_dict(self) -> dict:
        """The TOML form: ``{uniform = [lo, hi]}`` or ``{choice = [...]}``."""
        return {"choice": list(self.options)} if self.kind == "choice" else {"uniform": [self.low, self.high]}


@dataclass(frozen=True)
class RunPlan:
    """Run ``run``: its seed, its sampled values (``key -> value``) and the scenario they make."""

    run: int
    seed: int
    values: dict
    scenario: Scenario


@dataclass(frozen=True)
class CampaignSpec:
    """A validated spec: ``base`` is the scenario dict (``Scenario.to_dict()``) every run starts from."""

    scenario_source: str
    base: dict
    runs: int
    seed: int
    duration: float
    sample: tuple[tuple[str, Distribution], ...]
    falsify_sequences: int = 0

    def to_dict(self) -> dict:
        """Everything the campaign needs (no path): enough to rebuild the spec (:func:`spec_from_stored`)."""
        return {"scenario_source": self.scenario_source, "base": self.base, "runs": self.runs, "seed": self.seed,
                "duration": self.duration, "sample": {k: d.to_dict() for k, d in self.sample},
                "falsify": {"sequences": self.falsify_sequences}}

    @property
    def fingerprint(self) -> str:
        """sha256 of the spec without ``runs`` (a rerun with more runs extends the same campaign) and without
        the scenario's path (its content, ``base``, counts: a moved checkout resumes)."""
        data = self.to_dict()
        data.pop("runs")
        data.pop("scenario_source")
        return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()

    def plan(self, run: int) -> RunPlan:
        """The seed, samples and scenario of run ``run`` (pure: the same on any machine)."""
        seed = run_seed(self.seed, run)
        rng = np.random.default_rng([seed, 0])
        values = {key: dist.draw(rng) for key, dist in self.sample}
        data = json.loads(json.dumps(self.base))
        data["duration"] = self.duration
        for key, value in values.items():
            _set_dotted(data, key, value)
        try:
            scenario = scenario_from_dict(data)
        except TubekitError as exc:
            named = str(getattr(exc, "field", getattr(exc, "name", "")))
            field = next((k for k in values if named.startswith(k)), None)
            if field is None:
                raise ConfigError("sample", "values the scenario accepts", values, str(exc)) from None
            raise ConfigError(f"sample.{field}", "a value the scenario accepts", values[field], str(exc)) from None
        return RunPlan(run, seed, values, scenario)


def require_dependencies() -> None:
    """Raise ImportError naming the extra when dask.distributed or pyarrow is missing (cheap: nothing imported)."""
    for module in ("distributed", "pyarrow"):
        if importlib.util.find_spec(module) is None:
            raise ImportError(f"No module named '{module}' (pip install -e '.[campaign]')")


def run_seed(seed: int, run: int) -> int:
    """The integer seed of run ``run``: child ``run`` of ``SeedSequence(seed)``, one 63-bit word."""
    child = np.random.SeedSequence(seed, spawn_key=(run,))
    return int(child.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))


def certificate_key(scenario: Scenario) -> str:
    """What ``verify.certify`` reads of ``scenario``, as text: equal keys share one certificate."""
    data = scenario.to_dict()
    for dotted in NOT_CERTIFICATE_INPUTS:
        *parents, leaf = dotted.split(".")
        table = data
        for part in parents:
            table = table.get(part, {})
        table.pop(leaf, None)
    return json.dumps(data, sort_keys=True)


def _set_dotted(data: dict, key: str, value: Any) -> None:
    *parents, leaf = key.split(".")
    table = data
    for part in parents:
        table = table.setdefault(part, {})
    table[leaf] = value


def _get_dotted(data: dict, key: str) -> Any:
    """The base value at ``key`` (None when its table exists but the leaf is not set)."""
    *parents, leaf = key.split(".")
    table: Any = data
    for part in parents:
        table = table.get(part) if isinstance(table, dict) else None
        if not isinstance(table, dict):
            raise ConfigError(f"sample.{key}", "a dotted key of the scenario (e.g. disturbance.amplitude)", key)
    return table.get(leaf)


def _number(field: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigError(field, "a finite number", value)
    return float(value)


def _uniform(field: str, bounds: Any, base: Any) -> Distribution:
    if not isinstance(bounds, list) or len(bounds) != 2:
        raise ConfigError(field, "[lo, hi] (vectors: [[lo...], [hi...]])", bounds)
    if isinstance(base, list):
        lo, hi = bounds
        if not (isinstance(lo, list) and isinstance(hi, list) and len(lo) == len(hi) == len(base)):
            raise ConfigError(field, f"[[lo...], [hi...]] with {len(base)} numbers each (elementwise)", bounds)
        low = [_number(field, x) for x in lo]
        high = [_number(field, x) for x in hi]
    else:
        low, high = _number(field, bounds[0]), _number(field, bounds[1])
    if np.any(np.asarray(low) > np.asarray(high)):
        raise ConfigError(field, "lo <= hi (elementwise)", bounds)
    return Distribution("uniform", low, high)


def _distribution(key: str, entry: Any, base: dict) -> Distribution:
    field = f"sample.{key}"
    if not isinstance(entry, dict) or len(entry) != 1 or next(iter(entry)) not in ("uniform", "choice"):
        raise ConfigError(field, "{ uniform = [lo, hi] } or { choice = [...] }", entry)
    current = _get_dotted(base, key)
    if "uniform" in entry:
        return _uniform(f"{field}.uniform", entry["uniform"], current)
    options = entry["choice"]
    if not isinstance(options, list) or not options:
        raise ConfigError(f"{field}.choice", "a non-empty list of values", options)
    return Distribution("choice", options=tuple(options))


def _integer(field: str, value: Any, low: int, high: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low or (high is not None and value > high):
        raise ConfigError(field, f"an integer >= {low}" + (f" and <= {high}" if high is not None else ""), value)
    return value


def _base_scenario(source: Any, spec_dir: Path | None) -> tuple[str, Scenario]:
    if not isinstance(source, str) or not source:
        raise ConfigError("scenario", "a scenario TOML path (relative to the spec) or \"paper\"", source)
    if source == "paper":
        return source, paper_scenario()
    path = Path(source) if spec_dir is None or Path(source).is_absolute() else spec_dir / source
    try:
        return str(path), load_scenario(path)
    except ConfigError as exc:
        raise ConfigError("scenario", "a readable, valid scenario TOML", str(path), str(exc)) from None


def spec_from_dict(data: Any, spec_dir: Path | None = None) -> CampaignSpec:
    """Validate a parsed spec; relative scenario paths are taken from ``spec_dir``."""
    if not isinstance(data, dict):
        raise ConfigError("SPEC", "a TOML table", type(data).__name__)
    unknown = sorted(set(data) - set(SPEC_KEYS))
    if unknown:
        raise ConfigError(unknown[0], f"one of the keys {list(SPEC_KEYS)}", unknown[0])
    for key in ("scenario", "runs", "seed"):
        if key not in data:
            raise ConfigError(key, "a value (required)", None)
    source, scenario = _base_scenario(data["scenario"], spec_dir)
    runs = _integer("runs", data["runs"], 1, MAX_RUNS)
    seed = _integer("seed", data["seed"], 0)
    duration = _number("duration", data.get("duration", scenario.duration))
    require_one_period("duration", duration, scenario.controller.dt)
    base = scenario.to_dict()
    sample = data.get("sample", {})
    if not isinstance(sample, dict):
        raise ConfigError("sample", "a table of dotted scenario keys", sample)
    for key in sample:
        if key.split(".")[0] == "duration":
            raise ConfigError(f"sample.{key}", "a scenario key other than duration (set duration in the spec)", key)
    dists = tuple((key, _distribution(key, sample[key], base)) for key in sorted(sample))
    falsify = data.get("falsify", {"sequences": 0})
    if not isinstance(falsify, dict) or set(falsify) - {"sequences"}:
        raise ConfigError("falsify", "a table with the key 'sequences'", falsify)
    sequences = _integer("falsify.sequences", falsify.get("sequences", 0), 0, 1000)
    spec = CampaignSpec(source, base, runs, seed, duration, dists, sequences)
    spec.plan(0)  # the first run builds (a wrong key or value is named now)
    return spec


def load_spec(path: str | Path) -> CampaignSpec:
    """Read and validate ``SPEC.toml`` (:func:`spec_from_dict`); every error names its field."""
    p = Path(path)
    return spec_from_dict(read_toml(p, "SPEC"), p.resolve().parent)


def spec_from_stored(data: dict) -> CampaignSpec:
    """The spec stored in ``campaign.json`` (:meth:`CampaignSpec.to_dict`), without reading any file."""
    dists = tuple((key, _distribution(key, entry, data["base"])) for key, entry in sorted(data["sample"].items()))
    return CampaignSpec(data["scenario_source"], data["base"], int(data["runs"]), int(data["seed"]),
                        float(data["duration"]), dists, int(data["falsify"]["sequences"]))
