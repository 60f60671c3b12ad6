"""Actuation semantics: what an actuated crease is, and how a fold leaves the flat state.

Kept free of heavy imports (the command line reads these names).

**Actuated creases** (``Simulation(actuation=...)``, ``--actuation``):

* ``"equal"`` (default, the paper's): an actuated sub-strip weighs what a
  passive one does — a hinge with a rest angle. Where the model cannot meet
  every target at once (a binding vertex, conflicting targets, position
  targets) the actuated creases share the misfit with the rest.
* ``"angle"``: angle-controlled — actuated strips weigh ``ACTUATION_STIFFNESS``
  times their volume, as if a stiff actuator held each angle, so the passive
  creases and the panels give way and the actuated angles are reached.

Where every target can be met (the axis hinge on a rigid-foldable pattern)
both reach the same state; ``"equal"`` is the default because the stiffness
contrast of ``"angle"`` slows L-BFGS and can stall the rigid-body strategy
(``bench/accuracy.py``; `docs/architecture.md#branch-selection`).

**Branch selection by assignment** (``branch_floor_deg``, ``--branch-floor``):
the flat state is a bifurcation — a degree-4 vertex has two branches, a
Miura sheet many first-order flexes — so a fold driven from flat can jam or
take the wrong branch. A run that starts from a flat sheet (every crease
within the floor of 0°) with a crease driven and passive M/V creases first
folds with every passive M/V crease held at least ``BRANCH_FLOOR_DEG`` on its
assigned side, to a relative step of ``BRANCH_TOLERANCE``, then releases the
floor and runs to its own tolerance; from a folded state, or one already on
its branch (every passive M/V crease at least ``BRANCH_LEFT_DEG`` = 1e-3° on
its side: a sweep's later frames), there is no such stage. With the axis
hinge the stage mostly saves iterations; with the arc and Eq. 8 hinges it is
what makes mode B leave the flat state: `docs/architecture.md#branch-selection`.
"""
ACTUATIONS = ("equal", "angle")
DEFAULT_ACTUATION = "equal"
ACTUATION_STIFFNESS = 1e3  # weight multiplier of actuated strips under "angle"
BRANCH_FLOOR_DEG = 2.0  # degrees, default floor of the branch stage
BRANCH_TOLERANCE = 1e-6  # relative step at which the branch stage hands over
