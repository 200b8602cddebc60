"""benchmarks/compiled_plant.py: the kernel is a faithful transcription of the plant's RK4 (run uncompiled)."""

from __future__ import annotations

import numpy as np

from tubekit import paper_scenario
from tubekit.plant.kinematic import Plant

from .scripts import load_script


def _module():
    return load_script("benchmarks/compiled_plant.py", "bench_compiled_plant")


def test_the_kernel_source_equals_the_plant_step_bit_for_bit():
    """The kernel numba would compile, run as plain Python, gives the plant's own floats (the benchmark's
    ``bit_identical`` then measures only what compilation changes)."""
    mod = _module()
    sc = paper_scenario().with_changes(**{"disturbance.sway.amplitude": 0.02})
    plant = Plant.of(sc)
    (a0, a1, a2), (c0, c1, c2) = plant._amplitude, plant._constant
    const = (a0, a1, a2, c0, c1, c2, plant._current_rate, plant._sway_amplitude, plant._sway_rate,
             plant._sway_gain)
    rng = np.random.default_rng(3)
    for t in rng.uniform(0.0, 100.0, 50):
        x, v = tuple(rng.normal(size=4)), tuple(rng.uniform(-0.4, 0.4, 3))
        assert mod._kernel_source(float(t), *x, *v, 0.005, 2, *const)[:4] == plant._rk4_fused(float(t), x, v, 0.005, 2)
