"""The residual model of the rigid-body step: strip rows, pins, M/V side rows.

The energy is the paper's, E = Σ_e w_e‖C x_e − R_e T_e(φ_e)‖² (+ position
targets), the panels' terms identically zero since panels are rigid; each
strip row is √w (x_k − x̄ − R_e t_k) with t_k its bent shape at its bend
angle φ_e. A row per M/V crease keeps its panels' dihedral on the assigned
side (:func:`mv_side`). The normal equations are assembled strip by strip in
numba (:mod:`.normal`) on the layout's fixed pattern; J itself is never
formed. Units: mm, rad.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from elements.bending_hinge import bent_shapes, shape_derivatives

from ...errors import SimulationError
from . import normal
from .layout import mv_creases

ROUNDING = 64 * np.finfo(float).eps  # relative energy change that is rounding noise


def mv_side(t: np.ndarray, wall: float, slack: float) -> tuple[np.ndarray, np.ndarray]:
    """(value, slope) of an M/V side row's shape at ``t`` (C,) rad, the panels'
    dihedral signed toward the crease's assigned side, in (−π, π].

    0 on the assigned side (t ≥ −``slack``); t + ``slack`` where a crease crosses
    to the other side; beyond, back to 0 at t = −π with slope ``wall``: −π and
    +π are one dihedral, a crease folded flat, so a fold a hair past flat costs
    only its overshoot. Why this shape: `docs/architecture.md#mv-side-rows`."""
    t = np.ascontiguousarray(t, dtype=float).ravel()
    value, slope = np.empty_like(t), np.empty_like(t)
    normal.mv_side_many(t, wall, slack, value, slope)
    return value, slope


class ResidualModel:
    """Residuals r, their linearisation and energies at rigid-body states.

    Parameters
    ----------
    model : foldcore.model.Model
        Its strip weights (read at every step: actuation and stops change them),
        position targets and pattern.
    layout : UnknownLayout
    kinematics : Kinematics
    options : RigidOptions

    Attributes
    ----------
    sqrt_w : (S,) float
        √(strip weight), mm^1.5.
    shape : (8 S, 3) float
        The strips' bent shapes at the angles of the last :meth:`update_shapes`, mm.
    strip_targets : (S, 8, 3) float
        R_e t_k of the last :meth:`strip_rows`, mm.
    """

    def __init__(self, model, layout, kinematics, options):
        self.model, self.layout, self.kinematics = model, layout, kinematics
        self.wall, self.slack = options.mv_wall, options.mv_slack
        self._weights_read = None  # the model's strip-weight array sqrt_w was taken from
        self.sync_weights()
        s = len(layout.ids)
        self.shape = np.zeros((8 * s, 3))
        self.d_shape = np.zeros((8 * s, 3))
        self._shape_scratch = np.zeros((8 * s, 3))
        self._shape_phi, self._d_shape_current = np.zeros(s), False
        self._init_mv_rows(model.mesh, model.pattern, options.mv_stiffness)
        self._contact_at = None  # (positions, ContactState) of the last contact evaluation

    def sync_weights(self) -> None:
        """√w from the model's current strip weights (a new array is the sign of a change)."""
        weights = self.model.system.weights[self.model.hinge_index]
        if weights is self._weights_read:
            return
        self._weights_read = weights
        self.sqrt_w = np.sqrt(weights)

    def _init_mv_rows(self, mesh, pattern, stiffness: float) -> None:
        """M/V creases whose panels' dihedral is held on the assigned side: a row
        √μ·g(s·ρ) each, ρ the dihedral, s = +1 valley / −1 mountain (:func:`mv_side`).
        The strips' angle bounds alone let the panels cross to the other side."""
        crease = mv_creases(pattern, stiffness)
        self.mv_sign = np.where(pattern.assignments[crease] == "V", 1.0, -1.0)
        d2 = pattern.vertices[pattern.edges[crease, 1]] - pattern.vertices[pattern.edges[crease, 0]]
        self.mv_axis = np.column_stack([d2, np.zeros(len(crease))])
        self.mv_sqrt = np.sqrt(stiffness * self.model.system.reference_weight) \
            * mesh.hinge_width[crease]

    # -------------------------------------------------------------- shapes
    def update_shapes(self, phi: np.ndarray) -> None:
        """The strips' bent shapes T(φ) at ``phi`` (S,) rad into :attr:`shape`; their
        derivative dT/dφ waits for :meth:`shape_derivatives` (only a linearisation
        needs it)."""
        g = self.layout.hinges
        bent_shapes(g.group.indptr, g.group.rest, g.params, phi, self.shape)
        self._shape_phi, self._d_shape_current = np.array(phi, dtype=float), False

    def shape_derivatives(self) -> np.ndarray:
        """(S·8, 3) dT/dφ, mm/rad, at the angles of the last :meth:`update_shapes`."""
        if not self._d_shape_current:
            g = self.layout.hinges
            shape_derivatives(g.group.indptr, g.group.rest, g.params, self._shape_phi,
                              self._shape_scratch, self.d_shape)
            self._d_shape_current = True
        return self.d_shape

    def fit_rotations(self, x: np.ndarray, rot_e: np.ndarray) -> None:
        """Each strip's target rotation fitted exactly to ``x`` (Procrustes), into
        ``rot_e`` (S, 3, 3), at the current shapes."""
        normal.fit_strip_rotations(self.layout.ids, x, self.shape.reshape(-1, 8, 3), rot_e)

    # ----------------------------------------------------------- residuals
    def strip_rows(self, x: np.ndarray, rot_e: np.ndarray) -> np.ndarray:
        """(S, 8, 3) strip rows √w (x_k − x̄ − R_e t_k); the targets R_e t_k are kept in
        :attr:`strip_targets`."""
        s = len(self.layout.ids)
        self.strip_targets = np.empty((s, 8, 3))
        residual = np.empty((s, 8, 3))
        normal.strip_rows(self.layout.ids, x, rot_e, self.shape.reshape(-1, 8, 3), self.sqrt_w,
                          self.strip_targets, residual)
        return residual

    def pin_terms(self):
        """Position targets as (vertex ids (n,), √weights (n,), positions (n, 3)), or None."""
        model = self.model
        if not model.position_targets:
            return None
        targets = model.position_targets.values()
        reference = model.system.reference_weight
        return (np.concatenate([t.vertices for t in targets]),
                np.concatenate([np.full(len(t.vertices), np.sqrt(t.alpha * reference))
                                for t in targets]),
                np.concatenate([t.positions for t in targets]))

    def residuals(self, state) -> np.ndarray:
        """r: strip rows (24 S) then position-target rows then M/V rows; the shapes
        are updated to ``state.phi`` first."""
        self.update_shapes(state.phi)
        return self.residuals_at_shapes(state)

    def residuals_at_shapes(self, state) -> np.ndarray:
        """:meth:`residuals` with the strip shapes already those of ``state.phi``."""
        parts = [self.strip_rows(state.x, state.rot_e).ravel()]
        pins = self.pin_terms()
        if pins is not None:
            v, w, p = pins
            parts.append((w[:, None] * (state.x[v] - p)).ravel())
        if len(self.mv_sign):
            parts.append(self.mv_terms(state.rot_p)[0])
        return np.concatenate(parts) if len(parts) > 1 else parts[0]

    def mv_terms(self, rot_p):
        """(residual rows (C,), ∂ρ/∂ω of the left panel (C, 3)) of the M/V side rows."""
        lay = self.layout
        value, grad = np.empty(len(self.mv_sign)), np.empty((len(self.mv_sign), 3))
        normal.mv_terms(rot_p, lay.mv_left, lay.mv_right, self.mv_axis, self.mv_sign,
                        self.mv_sqrt, self.wall, self.slack, value, grad)
        return value, grad

    def trial_energy(self, state) -> float:
        """Energy of a trial state after refitting its strips' rotations in place
        (with contact, plus the barrier energy of its panels)."""
        self.update_shapes(state.phi)
        self.fit_rotations(state.x, state.rot_e)
        residual = self.residuals_at_shapes(state)
        strips = 24 * len(self.layout.ids)  # summed as before: the accept test is at rounding level
        energy = float((residual[:strips] ** 2).sum() + (residual[strips:] ** 2).sum())
        contact = self.contact_state(state.x)
        return energy if contact is None else energy + contact.energy

    # ------------------------------------------------------------- contact
    def contact_state(self, x: np.ndarray):
        """The model's contacts at positions x (cached for the last x), or None
        without contact."""
        contact = self.model.contact
        if contact is None:
            return None
        if self._contact_at is None or not np.array_equal(self._contact_at[0], x):
            self._contact_at = (x.copy(), contact.state(x))
        return self._contact_at[1]

    def forget_contact(self) -> None:
        """The contact model changed (its stiffness): the next evaluation is anew."""
        self._contact_at = None

    def contact_terms(self, state, with_hessian: bool):
        """(½ Pᵀ∇C (n_q,), lower triangle of ½ PᵀHP as COO or None) of the contact
        energy C at a state, P = ∂x/∂(panel, free-vertex unknowns); None when
        nothing touches. ½: the step's energy is rᵀr, its gradient Jᵀr."""
        contact = self.contact_state(state.x)
        if contact is None or not contact.active:
            return None
        model = self.model.contact
        p_map = self.kinematics.position_map(state)
        grad = 0.5 * (p_map.T @ model.gradient(contact).ravel())
        if not with_hessian:
            return grad, None
        hess = model.hessian(contact)
        return grad, sp.tril(0.5 * (p_map.T @ (hess @ p_map)), format="coo")

    def rounding_energy(self) -> float:
        """Energy of strip residuals of ``ROUNDING`` × the pattern's size in every row
        (mm⁵): what rounding leaves of an energy that should vanish."""
        return 24.0 * float(self.sqrt_w @ self.sqrt_w) * (ROUNDING * self.model.length_scale) ** 2

    # ------------------------------------------------------ linearisation
    def angle_columns(self, rot_e) -> np.ndarray:
        """(S, 8, 3) ∂(R T_k)/∂(crease angle) of passive strips (−R ∂T_k/∂φ / k), 0 else."""
        lay = self.layout
        pas = lay.passive_ids
        out = np.zeros((len(lay.ids), 8, 3))
        d_shape = self.shape_derivatives().reshape(-1, 8, 3)
        out[pas] = np.einsum("sij,skj->ski", rot_e[pas], d_shape[pas]) \
            * (-1.0 / lay.k_strip[pas])[:, None, None]
        return out

    def mv_rows(self, rot_p, n_columns: int):
        """(C, n_unknowns) Jacobian of the M/V rows: +∂ on the left panel's rotation
        columns, − on the right's."""
        lay = self.layout
        _, grad = self.mv_terms(rot_p)
        wrong = grad.any(axis=1)  # the other rows are 0 (no M/V crease on its wrong side: all)
        if not wrong.any():
            return sp.csr_matrix((len(self.mv_sign), n_columns))
        rows, cols, vals = [], [], []
        for panels, sign in ((lay.mv_left, 1.0), (lay.mv_right, -1.0)):
            col = lay.panel_col[panels]
            moving = np.flatnonzero((col >= 0) & wrong)
            for k in range(3):
                rows.append(moving)
                cols.append(col[moving] + k)
                vals.append(sign * grad[moving, k])
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(len(self.mv_sign), n_columns))

    def pin_rows(self):
        """(3 n_pin, 3N) Jacobian rows of the position targets w.r.t. positions, or None."""
        pins = self.pin_terms()
        if pins is None:
            return None
        v, w, _ = pins
        cols = (3 * v[:, None] + np.arange(3)).ravel()
        return sp.csr_matrix((np.repeat(w, 3), (np.arange(3 * len(v)), cols)),
                             shape=(3 * len(v), 3 * self.layout.n_vertices))

    def extra_rows(self, state):
        """Sparse Jacobian of the rows after the strips' (position targets, then M/V side
        rows), or None when there are none."""
        lay = self.layout
        parts = []
        pins = self.pin_rows()
        if pins is not None:
            n_hinge = 3 * len(lay.ids) + lay.n_folds
            parts.append(sp.hstack([pins @ self.kinematics.position_map(state),
                                    sp.csr_matrix((pins.shape[0], n_hinge))]))
        if len(self.mv_sign):
            parts.append(self.mv_rows(state.rot_p, lay.n_unknowns))
        if len(parts) < 2:
            return parts[0].tocsr() if parts else None
        return sp.vstack(parts).tocsr()

    def linearise(self, state) -> "Linearisation":
        """JᵀJ (values on the layout's fixed pattern), Jᵀr and r at a state, without
        forming J for the strips (:mod:`.normal`)."""
        lay = self.layout
        lay.build_columns()
        residual = self.residuals(state)
        s = len(lay.ids)
        lin = Linearisation(lay, self.sqrt_w, state, residual, self.strip_targets,
                            self.angle_columns(state.rot_e), self.extra_rows(state))
        contact = self.contact_state(state.x)
        if contact is not None and contact.active:
            lay.add_contacts(self.model.contact.touching(contact))
            lin.contact_energy = contact.energy
        data = np.zeros(len(lay.csc_indices))
        lin.grad = np.zeros(lay.n_unknowns)
        missing = normal.assemble(
            *lin.strip_args, lay.n_loc, residual[:24 * s].reshape(s, 8, 3), lay.rounds,
            lay.crease_ptr, lay.crease_strips, lay.csc_indptr, lay.csc_indices, data, lin.grad)
        if lin.extra is not None and lin.extra.nnz:  # (all zero: adds nothing)
            lin.grad += lin.extra.T @ residual[24 * s:]
            coo = sp.tril(lin.extra.T @ lin.extra, format="coo")  # the stored triangle
            missing += normal.add_entries(lay.csc_indptr, lay.csc_indices, data,
                                          coo.row.astype(np.int64), coo.col.astype(np.int64),
                                          coo.data)
        terms = self.contact_terms(state, with_hessian=True)
        if terms is not None:
            grad, coo = terms
            lin.grad[:len(grad)] += grad
            missing += normal.add_entries(lay.csc_indptr, lay.csc_indices, data,
                                          coo.row.astype(np.int64), coo.col.astype(np.int64),
                                          coo.data)
        if missing:
            raise SimulationError(f"solver 'rigid': {missing} normal-matrix entries outside "
                                  "the layout's pattern (a bug: please report it)")
        lin.normal = data
        return lin

    def gradient(self, state, residual: np.ndarray) -> np.ndarray:
        """Jᵀr (n_unknowns,) at ``state`` for its ``residual`` r, just computed (the strip
        targets it set are used); no normal matrix is assembled."""
        here = Linearisation(self.layout, self.sqrt_w, state, residual, self.strip_targets,
                             self.angle_columns(state.rot_e), self.extra_rows(state))
        grad = here.apply_transpose(residual)
        terms = self.contact_terms(state, with_hessian=False)
        if terms is not None:
            grad[:len(terms[0])] += terms[0]
        return grad


class Linearisation:
    """The step's linear model at one state: r, Jᵀr, JᵀJ's values, and J·v / Jᵀu.

    The strips' rows come from :mod:`.normal` (no J is formed); the few rows
    after them (position targets, M/V side rows) are a small sparse matrix
    ``extra``.
    """

    def __init__(self, layout, sqrt_w, state, residual, targets, d_targets, extra):
        self.residual, self.extra = residual, extra
        self.n_strip_rows = 24 * len(layout.ids)
        self.n_unknowns = layout.n_unknowns
        self.contact_energy = 0.0  # barrier energy at the state, mm⁵ (0 without contact)
        self.strip_args = (layout.ids, state.x, state.c_p, layout.strip_side, layout.off_panel,
                           layout.strip_alpha, layout.own_off, layout.off_w, layout.off_phi,
                           layout.loc_cols, sqrt_w, targets, d_targets)
        self.grad = self.normal = None

    def apply(self, v: np.ndarray) -> np.ndarray:
        """J·v (rows as the residual) for an increment v (n_unknowns,)."""
        out = np.empty((self.n_strip_rows // 24, 8, 3))
        normal.apply_jacobian(*self.strip_args, v, out)
        if self.extra is None:
            return out.ravel()
        return np.concatenate([out.ravel(), self.extra @ v])

    def apply_transpose(self, u: np.ndarray) -> np.ndarray:
        """Jᵀ·u (n_unknowns,) for row values u (rows as the residual)."""
        grad = np.zeros(self.n_unknowns)
        m = self.n_strip_rows
        normal.apply_transpose(*self.strip_args, u[:m].reshape(-1, 8, 3), grad)
        if self.extra is not None:
            grad += self.extra.T @ u[m:]
        return grad
