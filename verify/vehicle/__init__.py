"""The dynamic vehicle inside the theorem (issue 22): the velocity loop's error bound derived in Arb.

``model`` (the vehicle in Arb: coefficient boxes, n(ν), its gradient), ``response`` (rigorous impulse-response
sums), ``bound`` (:func:`verify.vehicle.bound.velocity_loop_bound`, the fixed point and its conditions),
``result`` (the typed ``LoopBound``), ``compose`` (:func:`verify.vehicle.compose.solve_dynamic`: the loop bound
with ω̄, the tube and the backup, as a checked fixed point). Import the submodules; this face imports nothing.
"""

__all__: list[str] = []
