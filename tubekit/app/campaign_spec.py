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

``plant.truth`` takes ``{ box = true }``: every coefficient the scenario's vehicle gives as an interval
is drawn uniformly inside it (the plant as simulated; the certificate covers the whole box, so every
run shares it)::

    "plant.truth" = { box = true }

``obstacles`` takes a third kind, a cluster drawn afresh for every run (:func:`draw_cluster`)::

    "obstacles" = { cluster = { count = [3, 7], radius = [0.15, 0.4], gap = [0.01, 0.3],
                                center = [[-1.0, 2.0, -0.2], [1.0, 4.0, 0.2]], margin = 0.15 } }

Run ``k`` gets its own seed, ``SeedSequence(seed).spawn(runs)[k]`` reduced to one integer
(:func:`run_seed`); its samples are drawn from ``default_rng([run_seed, 0])`` in the sorted order
of the keys, its disturbance sequences (worker side) from ``default_rng([run_seed, 1])``. Run ``k``
is therefore the same whatever ``runs`` is, whatever the worker, the order or the scheduler.
Every error is a :class:`~tubekit.exceptions.ConfigError` naming the spec field.
"""

from __future__ import annotations

import hashlib
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
           "spec_from_stored", "SPEC_KEYS",
           "draw_cluster", "CLUSTER_KEYS"]
#: Upper bound on ``runs`` (a typo guard; 10^6 run files is already a lot).
MAX_RUNS = 1_000_000
#: Keys of an ``obstacles = { cluster = {...} }`` entry (``margin`` optional, m).
CLUSTER_KEYS = ("count", "radius", "gap", "center", "margin")
#: Hexagonal lattice offsets (units of the spacing): the centre, its 6 neighbours, then the next 12.
_HEX = ([(0.0, 0.0)] + [(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)]
        + [(2 * math.cos(k * math.pi / 3), 2 * math.sin(k * math.pi / 3)) for k in range(6)]
        + [(math.sqrt(3) * math.cos(k * math.pi / 3 + math.pi / 6), math.sqrt(3) * math.sin(k * math.pi / 3 + math.pi / 6))
           for k in range(6)])

#: Top-level keys of a spec.
SPEC_KEYS = ("scenario", "runs", "seed", "duration", "sample", "falsify")


@dataclass(frozen=True)
class Distribution:
    """``uniform`` on [lo, hi] (elementwise for vectors) or ``choice`` among ``options``."""

    kind: str
    low: Any = None
    high: Any = None
    options: tuple = ()

    def draw(self, rng: np.random.Generator) -> Any:
        """One value: a float, a list of floats (vector uniform), one of ``options`` or a cluster's obstacles."""
        if self.kind == "cluster":
            return draw_cluster(dict(self.options), rng)
        if self.kind == "box":  # one value per interval coefficient, in the order of ``options``
            return {name: float(rng.uniform(lo, hi)) for name, lo, hi in self.options}
        if self.kind == "choice":
            return self.options[int(rng.integers(len(self.options)))]
        value = rng.uniform(np.asarray(self.low, dtype=float), np.asarray(self.high, dtype=float))
        return value.tolist() if np.ndim(value) else float(value)

    def to_dict(self) -> dict:
        """The TOML form: ``{uniform = [lo, hi]}`` or ``{choice = [...]}``."""
        if self.kind == "cluster":
            return {"cluster": {k: v for k, v in self.options if k != "vehicle_radius"}}
        if self.kind == "box":
            return {"box": True}
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
        if any(dist.kind == "cluster" for _, dist in self.sample):
            data["obstacles"] = values["obstacles"] = _clear_of_start(data)  # the row records what ran
        try:
            scenario = scenario_from_dict(data)
        except TubekitError as exc:
            named = str(getattr(exc, "field", getattr(exc, "name", "")))
            field = next((k for k in values if named.startswith(k)), None)
            if field is None:
                raise ConfigError("sample", "values the scenario accepts", values, str(exc)) from None
            raise ConfigError(f"sample.{field}", "a value the scenario accepts", values[field], str(exc)) from None
        return RunPlan(run, seed, values, scenario)


def draw_cluster(params: dict, rng: np.random.Generator) -> list[dict]:
    """Obstacles ``[{center, radius}]`` of one cluster: ``count`` (integers lo..hi) equal spheres of ``radius``
    on a hexagonal lattice (horizontal, random rotation) about a ``center`` drawn in its box, neighbours
    ``(2 (vehicle_radius + margin) + 2 radius)(1 + gap)`` apart (``vehicle_radius`` and ``margin`` in
    ``params``): separated as ``certify`` requires when the position margin is at most ``margin``."""
    count = int(rng.integers(int(params["count"][0]), int(params["count"][1]) + 1))
    radius = float(rng.uniform(*params["radius"]))
    gap = float(rng.uniform(*params["gap"]))
    centre = rng.uniform(np.asarray(params["center"][0], dtype=float), np.asarray(params["center"][1], dtype=float))
    turn = float(rng.uniform(0.0, math.pi / 3))
    spacing = (2 * (params["vehicle_radius"] + params.get("margin", 0.0)) + 2 * radius) * (1.0 + gap)
    c, s = math.cos(turn), math.sin(turn)
    return [{"center": [float(centre[0] + spacing * (a * c - b * s)), float(centre[1] + spacing * (a * s + b * c)),
                        float(centre[2])], "radius": radius} for a, b in _HEX[:count]]


def _clear_of_start(data: dict) -> list[dict]:
    """The sampled obstacles that leave the start's vehicle ball clear (a start inside one certifies nothing)."""
    start = np.asarray(data["initial_state"][:3], dtype=float)
    rbar = float(data["vehicle_radius"])
    return [o for o in data.get("obstacles", [])
            if np.linalg.norm(np.asarray(o["center"], dtype=float) - start) > o["radius"] + rbar]


def _cluster(field: str, params: Any, base: dict) -> Distribution:
    """Validate ``{ cluster = { count, radius, gap, center, margin } }``; ``vehicle_radius`` from the base."""
    if not isinstance(params, dict) or set(params) - set(CLUSTER_KEYS) or set(CLUSTER_KEYS[:4]) - set(params):
        raise ConfigError(field, f"a table with the keys {list(CLUSTER_KEYS[:4])} (and optionally 'margin')", params)
    count = params["count"]
    if not (isinstance(count, list) and len(count) == 2 and all(isinstance(n, int) and not isinstance(n, bool)
                                                                for n in count) and 1 <= count[0] <= count[1] <= len(_HEX)):
        raise ConfigError(f"{field}.count", f"[lo, hi] integers with 1 <= lo <= hi <= {len(_HEX)}", count)
    for name, low in (("radius", 1e-9), ("gap", 0.0)):
        pair = _uniform(f"{field}.{name}", params[name], None)
        if pair.low < low:
            raise ConfigError(f"{field}.{name}", f"[lo, hi] with lo >= {low:g}", params[name])
    _uniform(f"{field}.center", params["center"], [0.0, 0.0, 0.0])
    margin = _number(f"{field}.margin", params.get("margin", 0.0))
    if margin < 0:
        raise ConfigError(f"{field}.margin", "a number >= 0 (m)", margin)
    options = {**params, "margin": margin, "vehicle_radius": float(base["vehicle_radius"])}
    return Distribution("cluster", options=tuple(sorted(options.items())))


def run_seed(seed: int, run: int) -> int:
    """The integer seed of run ``run``: child ``run`` of ``SeedSequence(seed)``, one 63-bit word."""
    child = np.random.SeedSequence(seed, spawn_key=(run,))
    return int(child.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))


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
    if key == "obstacles" and isinstance(entry, dict) and list(entry) == ["cluster"]:
        return _cluster(f"{field}.cluster", entry["cluster"], base)
    if key == "plant.truth":
        return _coefficient_box(field, entry, base)
    if not isinstance(entry, dict) or len(entry) != 1 or next(iter(entry)) not in ("uniform", "choice"):
        raise ConfigError(field, "{ uniform = [lo, hi] } or { choice = [...] }"
                          + (" or { cluster = {...} }" if key == "obstacles" else ""), entry)
    current = _get_dotted(base, key)
    if "uniform" in entry:
        return _uniform(f"{field}.uniform", entry["uniform"], current)
    options = entry["choice"]
    if not isinstance(options, list) or not options:
        raise ConfigError(f"{field}.choice", "a non-empty list of values", options)
    return Distribution("choice", options=tuple(options))


def _coefficient_box(field: str, entry: Any, base: dict) -> Distribution:
    """``{ box = true }``: the base vehicle's interval coefficients, each drawn uniformly in its interval (X_max of a
    vehicle whose thrust is tied to its drag, ``top_speed``, is derived from the draw instead)."""
    if entry != {"box": True}:
        raise ConfigError(field, "{ box = true } (every interval coefficient of the vehicle drawn in its interval)",
                          entry)
    plant = scenario_from_dict(base).plant
    if not plant.dynamic:
        raise ConfigError(field, "a base scenario on the dynamic plant ([plant] kind = \"dynamic\"): the kinematic "
                          "plant simulates no coefficient", plant.kind)
    params = plant.params
    names = params.free_fields  # a thrust tied to the drag is derived from the drawn hull, never drawn itself
    if not names:
        raise ConfigError(field, "a vehicle with at least one coefficient given as an interval [lo, hi]",
                          base.get("plant", {}).get("vehicle"))
    return Distribution("box", options=tuple((n, *params.interval(n)) for n in names))


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
