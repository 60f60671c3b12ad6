"""The rigid-body engine: panels as rigid bodies, Levenberg–Marquardt on the hinge energy.

Why: the paper's local/global map moves a long panel only through its thin
hinge faces, so its iteration count grows with (panel length / thickness)².
Here every rigid panel is a rigid body (rotation R_p, centroid c_p; its
vertices follow exactly), so a panel's rotation is one unknown of the step
whatever its length (`docs/architecture.md#the-rigid-body-strategy`).

:class:`RigidBodySolver` holds the configuration and composes collaborators
with one job each: :class:`.layout.UnknownLayout` (the unknowns and their
columns), :class:`.state.Kinematics` (how an increment moves the state),
:class:`.residual.ResidualModel` (residuals, linearisation, energies),
:class:`.step.LevenbergMarquardt` (the step and its damping),
:class:`.stopping.StoppingRule` (when a run may end) and
:class:`.handover.HandOver` (adopting a coarse twin's state). Units: mm, rad.
"""
from __future__ import annotations

import numpy as np

from elements.bending_hinge import FLOOR, MAX_ANGLE, SIGN, TARGET, estimate_angles

from ...errors import SimulationError
from .handover import HandOver
from .layout import UnknownLayout
from .residual import ResidualModel
from .state import Kinematics, State, exp_so3, log_so3
from .step import LevenbergMarquardt
from .stopping import StoppingRule


class RigidBodySolver:
    """One Levenberg–Marquardt iteration per :meth:`step` on a model's rigid panels.

    Parameters
    ----------
    model : foldcore.model.Model
        Mesh, hinge parameters (targets read at every step, so fold angles may
        change between steps), position targets and linear-solver backend.
    progress : foldcore.convergence.Progress
        The run's stage (a branch stage takes no extrapolation).
    options : RigidOptions

    Attributes
    ----------
    x : (N, 3) float
        Positions, mm (panels exactly rigid).
    rot_p, c_p : (P, 3, 3), (P, 3)
        Panel rotations and centroids (mm).
    y : (F, 3) float
        Hinge-interior vertices, mm.
    rot_e : (S, 3, 3) float
        Strip target rotations.
    phi : (S,) float
        Strip bend angles, rad.
    lo, hi : (n_folds,) float
        Each passive crease's angle interval, rad.
    """

    def __init__(self, model, progress, options):
        mesh = model.mesh
        extra = set(mesh.groups) - {"rigid_panel", "bending_hinge"}
        if mesh.panel_group != "rigid_panel" or extra:
            raise SimulationError("solver 'rigid' needs rigid panels and bending hinges only "
                                  f"(mesh has {sorted(mesh.groups)}); use solver='paper'")
        self.model, self.progress, self.options = model, progress, options
        self.backend = model.system.backend
        self.layout = UnknownLayout(model, options.mv_stiffness)
        self.kinematics = Kinematics(self.layout)
        self.rot_p, self.c_p = self.kinematics.fit_panels(model.x)
        self.y = model.x[self.layout.free].copy()
        self.residual = ResidualModel(model, self.layout, self.kinematics, options)
        self.phi = np.zeros(len(self.layout.ids))
        self.rot_e = np.tile(np.eye(3), (len(self.layout.ids), 1, 1))
        self.lm = LevenbergMarquardt(self, options)
        self.stopping = StoppingRule(self, options)
        self.handover = HandOver(self)
        self.ends = []  # the states two earlier runs ended in (a path's predictor)
        self.fitted = False  # the strips' rotations fitted to x
        self.x = self.kinematics.positions(self.rot_p, self.c_p, self.y)

    # ----------------------------------------------------------------- state
    def state(self) -> State:
        return State(self.x, self.rot_p, self.c_p, self.y, self.rot_e, self.phi)

    def set_state(self, state: State) -> None:
        self.x, self.rot_p, self.c_p, self.y, self.rot_e, self.phi = state

    @property
    def laid_out(self) -> bool:
        """Whether the unknowns' layout exists (built by the first step)."""
        return self.layout.laid_out

    def fold_edges(self) -> np.ndarray:
        """(n_folds,) pattern edge of each passive crease's angle unknown."""
        return self.layout.fold_edges()

    def folds(self) -> np.ndarray:
        """(n_folds,) current bend of each passive crease, rad (order of :meth:`fold_edges`)."""
        return self.layout.folds(self.phi)

    # ------------------------------------------------------------------ step
    def step(self) -> tuple[float, float]:
        """One Levenberg–Marquardt iteration (:class:`.step.LevenbergMarquardt`): (E
        before, mm⁵; largest vertex move of the step tried, mm)."""
        self.residual.sync_weights()
        self.read_targets()
        self.layout.build_columns()
        self.residual.update_shapes(self.phi)
        if not self.fitted:  # strips' rotations start at their exact fit
            self.rot_e = np.empty((len(self.layout.ids), 3, 3))
            self.residual.fit_rotations(self.x, self.rot_e)
            self.fitted = True
        energy, moved = self.lm.step()
        self.stopping.observe(energy)
        return energy, moved

    def read_targets(self) -> None:
        """Angles of actuated strips from the hinge parameters; set up newly passive creases.

        A crease that becomes passive starts from the sum of its strips' Eq. 9
        estimates, spread evenly (one arc) and clamped to its interval; an M/V
        crease that starts flatter than the pre-bend ``seed`` gets it, in its
        assigned direction (once: afterwards its angle is an unknown)."""
        lay = self.layout
        params = lay.hinges.params
        passive = np.isnan(params[:, TARGET])
        sign = params[:, SIGN]
        hi = np.where(sign < 0, -params[:, FLOOR], params[:, MAX_ANGLE])
        lo = np.where(sign > 0, params[:, FLOOR], -params[:, MAX_ANGLE])
        # position targets or obstacles hold the rigid motion: no panel is fixed
        contact = self.model.contact
        pinned = bool(self.model.position_targets) or (
            contact is not None and contact.obstacles is not None)
        relayout = lay.pinned != pinned  # which panel is fixed
        if lay.passive is None or relayout or not np.array_equal(passive, lay.passive):
            self._new_passive(passive, pinned, sign)
        first = np.zeros(lay.n_folds, dtype=np.int64)
        first[lay.passive_of[::-1]] = lay.passive_ids[::-1]
        self.lo, self.hi = lo[first] * lay.k_strip[first], hi[first] * lay.k_strip[first]
        lay.set_folds(np.clip(lay.folds(self.phi), self.lo, self.hi), self.phi)
        self.phi[~passive] = params[~passive, TARGET]

    def _new_passive(self, passive, pinned: bool, sign) -> None:
        """A new set of passive creases: their starting angles and the new layout."""
        lay = self.layout
        old = lay.passive if lay.passive is not None else np.zeros_like(passive)
        newly = passive & ~old
        estimate = np.zeros(len(self.phi))
        g = lay.hinges.group
        estimate_angles(self.x, g.indptr, g.indices, estimate)
        self.phi[newly] = estimate[newly]
        lay.set_passive(passive, pinned)
        fold = lay.folds(self.phi)
        seed = np.sign(sign[lay.passive_ids]) * self.options.seed * lay.k_strip[lay.passive_ids]
        flat = np.abs(fold[lay.passive_of]) < np.abs(seed)
        self.phi[lay.passive_ids] = np.where(flat, seed, fold[lay.passive_of]) \
            / lay.k_strip[lay.passive_ids]

    # ------------------------------------------------------------- verdict
    @property
    def distance(self) -> float:
        """Estimated distance left after the last step, mm."""
        return self.stopping.distance

    @property
    def energy_scale(self) -> float:
        return self.stopping.energy_scale

    @property
    def lam(self) -> float:
        return self.lm.lam

    @property
    def solve_time(self) -> float:
        return self.lm.solve_time

    def settled(self, moved: float, tolerance: float) -> bool:
        """:meth:`.stopping.StoppingRule.settled`."""
        return self.stopping.settled(moved, tolerance)

    def stalls(self, moved: float, relative: float) -> bool:
        """:meth:`.stopping.StoppingRule.stalls`."""
        return self.stopping.stalls(moved, relative)

    def new_run(self) -> None:
        """A run starts: its energy scale starts afresh, the damping at most its start."""
        self.stopping.new_run()
        self.lm.new_run()

    def release_factor(self) -> None:
        """Free the normal matrix's factorisation (the next step analyses the pattern
        again): a coarse twin's, at the end of a fold from rest, whose memory the
        mesh's certificate needs."""
        self.lm.factor = None

    # --------------------------------------------------------- other states
    def adopt(self, rot_p, c_p, fold_of_edge, energy_scale: float = 0.0,
              lam: float | None = None) -> None:
        """Continue from another model's state: :meth:`.handover.HandOver.adopt`."""
        lam = self.options.lambda_start if lam is None else lam
        self.handover.adopt(rot_p, c_p, fold_of_edge, energy_scale, lam)

    def strips_placed_within(self, limit: float) -> bool:
        """:meth:`.handover.HandOver.strips_placed_within`."""
        return self.handover.strips_placed_within(limit)

    def resync(self, x: np.ndarray) -> None:
        """Continue from positions ``x`` (N, 3) mm set since this engine last stepped
        (e.g. by an L-BFGS phase): panels refitted, strip rotations refitted at the
        next step; a no-op when ``x`` is the engine's own state."""
        if x is self.x or np.array_equal(x, self.x):
            return
        self.ends = []
        self.rot_p, self.c_p = self.kinematics.fit_panels(x)
        self.y = x[self.layout.free].copy()
        self.x = self.kinematics.positions(self.rot_p, self.c_p, self.y)
        self.fitted = False
        self.lm.forget()

    # ------------------------------------------------------------------ path
    def record_end(self) -> None:
        """Keep the state a run ended in (the last two: :meth:`predict`)."""
        self.ends = (self.ends + [self.state()])[-2:]

    def forget_ends(self) -> None:
        self.ends = []

    def predict(self, ratio: float) -> bool:
        """Extrapolate along the last two run ends: panel centroids and angles ≈ end₁ +
        ratio·(end₁ − end₀), rotations on their geodesic (exp(ratio·log(R₁R₀ᵀ))·R₁),
        hinge-interior vertices carried by their panels' motion from end₁ (a linear
        guess would strain the strips by O(increment²)). Returns whether it did (two
        ends kept and the engine still at the last)."""
        if len(self.ends) < 2 or not np.array_equal(self.ends[-1].x, self.x):
            return False
        old, new = self.ends
        turn = log_so3(new.rot_p @ np.transpose(old.rot_p, (0, 2, 1)))
        self.rot_p = exp_so3(ratio * turn) @ new.rot_p
        self.c_p = new.c_p + ratio * (new.c_p - old.c_p)
        self.y = self.kinematics.carry(new, self.rot_p, self.c_p)
        self.phi = new.phi + ratio * (new.phi - old.phi)
        self.x = self.kinematics.positions(self.rot_p, self.c_p, self.y)
        self.fitted = False
        self.lm.forget()
        return True
