"""Contact between parts (panels, hinge strips): IPC's barrier potential and continuous
collision detection.

Geometry comes from the IPC Toolkit (``ipctk``, Li et al., "Incremental
Potential Contact", 2020): its point–triangle and edge–edge distances, the
log barrier b(d) that is zero from the activation distance d̂ on and grows
without bound as d → 0, its gradient and PSD-projected Hessian, and a
conservative continuous collision check (additive CCD) that bounds how far a
straight-line step may go before any two triangles meet. foldcore's own part
is which pairs to ask it about (:class:`~.solids.PartSolids`): only pairs of
parts (panels, hinge strips) the broad phase cannot prove apart, each as a
two-body collision mesh (cached), so a sheet with nothing near costs a box
test and a slab test per step. Why ipctk and why part pairs: `docs/architecture.md#contact`.

Units: positions mm; the contact energy κ Σ b is in the model's energy unit
(mm⁵, the strips' weighted squared distances), its gradient (the contact
force, with the sign reversed) in mm⁴.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .obstacles import ObstacleContacts
from .solids import JoinedZones, PartSolids

#: Share of a straight-line step taken up to the first touch (IPC's 0.8–0.9).
CCD_RESCALING = 0.9
#: Joined panels touch with their faces this share of H closer together
#: (:class:`~.solids.JoinedZones`): faces that meet by design at a flat fold stay apart.
JOINED_SHARE = 2e-5
#: Depth of the band along a crease in which its hinge, not contact, decides how
#: its two panels meet (:class:`~.solids.JoinedZones`), × the crease's hinge width.
HINGE_ZONE = 1.0
#: κ doubles while the smallest gap of unjoined pairs is below this share of d̂ and
#: shrinking (IPC's adaptive stiffness), up to ``MAX_STIFFENING`` × its start.
TIGHT_GAP = 1e-3
MAX_STIFFENING = 1e8


def load_ipctk():
    """ipctk, its sums pinned to one thread: with its default threads the same run
    gave different results at rounding level from one time to the next (reductions
    in a varying order), which contact's cut steps carry on to the fold; each call
    here works on one small pair mesh, where its threads buy nothing."""
    import ipctk  # an import only runs that ask for contact pay for

    if ipctk.get_num_threads() != 1:
        ipctk.set_num_threads(1)
    return ipctk


def needs_stiffening(gap: float, last: float, dhat: float, kappa: float,
                     start: float) -> bool:
    """IPC's adaptive stiffness rule: κ doubles where the smallest gap (mm) is below
    ``TIGHT_GAP`` × d̂ and smaller than ``last`` (the previous check's), while κ is
    below ``MAX_STIFFENING`` × its ``start``."""
    return gap < TIGHT_GAP * dhat and gap < last and kappa < MAX_STIFFENING * start


@dataclass(frozen=True)
class ContactSettings:
    """How parts touch.

    Attributes
    ----------
    activation : float
        d̂ relative to the sheet thickness H: the barrier acts on pairs closer than
        activation · H (default 0.01: 1 % of H).
    stiffness : float
        κ relative to the model's reference weight (dimensionless factor).
    """

    activation: float = 0.01
    stiffness: float = 1.0

    def __post_init__(self):
        for name in ("activation", "stiffness"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise ValueError(f"contact.{name} must be a finite number > 0, got {value!r}")


@dataclass
class ContactState:
    """The contacts at one set of positions.

    Attributes
    ----------
    pairs : (K, 2) int
        Part pairs (:class:`~.solids.PartSolids`: panels, then strips) with at
        least one primitive pair within d̂.
    gaps : (K,) float
        Each pair's smallest distance, mm.
    joined : (K,) bool
        Whether a crease joins the pair (they touch by design at a flat fold).
    energy : float
        κ Σ b over every active primitive pair, mm⁵.
    obstacle_pairs : (L, 2) int
        (part, obstacle) pairs within d̂.
    obstacle_gaps : (L,) float
        Their smallest distances, mm.
    """

    pairs: np.ndarray
    gaps: np.ndarray
    energy: float
    _terms: list  # (pair vertices (n,), collisions, collision mesh, local positions, …)
    joined: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    obstacle_pairs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    obstacle_gaps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    _obstacle_of: list = field(default_factory=list)  # obstacle of each term (−1: parts)

    @property
    def active(self) -> bool:
        """Whether any barrier term acts (between parts or with an obstacle)."""
        return bool(self._terms)


class ContactModel:
    """Barrier energy, its derivatives and collision-free step fractions of a mesh's
    parts: rigid panels and hinge strips.

    Parameters
    ----------
    mesh, pattern
        The thick mesh and its crease pattern.
    reference_weight : float
        The model's reference weight (mm³): κ = ``settings.stiffness`` × it.
    settings : ContactSettings
    obstacles : sequence of :class:`~.obstacles.Obstacle`
        Fixed meshes the parts touch but never pass (:mod:`.obstacles`).
    """

    def __init__(self, mesh, pattern, reference_weight: float,
                 settings: ContactSettings | None = None, obstacles=()):
        self.settings = settings or ContactSettings()
        self.solids = PartSolids(mesh, pattern)
        self.zones = JoinedZones(self.solids, mesh, pattern,
                                 HINGE_ZONE * mesh.hinge_width[self.solids.joined_crease],
                                 JOINED_SHARE)
        self.dhat = self.settings.activation * float(mesh.thickness)
        self.kappa = self.settings.stiffness * float(reference_weight)
        #: d̂ of joined pairs, mm: half the gap their thinned faces keep at a flat fold
        self.dhat_joined = 0.5 * JOINED_SHARE * float(mesh.thickness)
        self.n_vertices = mesh.n_vertices
        self._rest = mesh.rest_positions
        self._meshes: dict = {}
        ipctk = load_ipctk()
        self._potential = self._potentials()
        self._ccd = ipctk.AdditiveCCD(conservative_rescaling=CCD_RESCALING)
        self.obstacles = ObstacleContacts(self.solids, obstacles, self._potential[False],
                                          self._ccd) if len(obstacles) else None
        self._kappa_start, self._last_gap = self.kappa, np.inf
        #: part pairs that cut the last step checked (:meth:`free_fraction`) short
        self.blocking: list = []

    def _potentials(self) -> dict:
        """The barrier potentials of unjoined (False) and joined (True) pairs at κ."""
        ipctk = load_ipctk()
        return {False: ipctk.BarrierPotential(self.dhat, self.kappa),
                # κ × d̂/d̂_j: a force at a gap of d̂_j/2 as large as κ's at d̂/2 … within a
                # factor ln: of the variants tried (×1, ×d̂/d̂_j, ×(d̂/d̂_j)²) the fewest steps
                True: ipctk.BarrierPotential(self.dhat_joined,
                                             self.kappa * self.dhat / self.dhat_joined)}

    def twin(self, mesh, pattern) -> "ContactModel":
        """This contact on another thickening of the same pattern (the rigid
        strategy's coarse twin: the same panels with fewer strip vertices): the same
        settings, κ and obstacles."""
        obstacles = self.obstacles.obstacles if self.obstacles is not None else ()
        return ContactModel(mesh, pattern, self.kappa / self.settings.stiffness,
                            self.settings, obstacles)

    def take_over(self, other: "ContactModel", panels: np.ndarray) -> None:
        """Go on from ``other``'s run (a twin's, :meth:`twin`): its κ and the pairs
        that cut its last step short, its panel p being this model's panels[p] (its
        strips this model's strips of the same creases)."""
        if other.kappa != self.kappa:
            self.kappa = other.kappa
            self._potential = self._potentials()
            if self.obstacles is not None:
                self.obstacles.potential = self._potential[False]
        self._last_gap = other._last_gap
        own = self.solids.part_of(other.solids, panels)
        self.blocking = [tuple(sorted((int(own[a]), int(own[b])))) for a, b in other.blocking]

    def stiffen(self, state: "ContactState") -> bool:
        """IPC's adaptive stiffness: doubles κ where the smallest gap of unjoined pairs
        and obstacles at ``state`` is below ``TIGHT_GAP`` × d̂ and smaller than at the
        last call (a load the barrier holds only at a vanishing gap, where every step
        is cut short); True when κ changed (energies at earlier states are stale)."""
        gaps = np.concatenate([state.gaps[~state.joined], state.obstacle_gaps])
        gap = float(gaps.min()) if len(gaps) else np.inf
        last, self._last_gap = self._last_gap, gap
        if not needs_stiffening(gap, last, self.dhat, self.kappa, self._kappa_start):
            return False
        self.kappa *= 2.0
        self._potential = self._potentials()
        if self.obstacles is not None:
            self.obstacles.potential = self._potential[False]
        return True

    # -------------------------------------------------------------- pairs
    def candidates(self, x: np.ndarray, margin: float) -> np.ndarray:
        """(K, 2) part pairs, not left out (joined panels, strips that meet at a
        vertex), not proved farther apart than ``margin`` mm."""
        lo, hi = self.solids.boxes(x)
        pairs = self.solids.pairs_near(lo, hi, margin)
        if len(pairs):
            pairs = pairs[self.solids.gap_bounds(x, pairs) < margin]
        return pairs

    def _joined_near(self, x: np.ndarray, margin: float):
        """((K,) indices of the joined pairs whose trimmed panels
        (:class:`~.solids.JoinedZones`) are not proved ``margin`` apart, their
        trimmed positions or None where no pair is joined)."""
        zones = self.zones
        if not len(zones.pairs):
            return np.zeros(0, dtype=np.int64), None
        y = zones.positions(x)
        which = np.arange(len(zones.pairs))
        return which[zones.gap_bounds(y, which) < margin], y

    def _terms_at(self, x: np.ndarray, joined: bool):
        """[(joined, (a, b), collision mesh, model vertex ids, pull-back, local
        positions)] of every pair to evaluate at x: unjoined pairs within d̂ on the
        panels as they are, joined pairs (where ``joined``) within their d̂ on their
        trimmed panels."""
        out = []
        for a, b in self.candidates(x, self.dhat):
            mesh, ids, pull = self._pair_mesh(int(a), int(b))
            out.append((False, (a, b), mesh, ids, pull, np.asfortranarray(x[ids])))
        if joined:
            which, y = self._joined_near(x, self.dhat_joined)
            for k in which:
                mesh, ids, pull = self._zone_mesh(int(k))
                out.append((True, tuple(self.zones.pairs[k]), mesh, ids, pull,
                            np.asfortranarray(y[self.zones.rows(int(k))])))
        return out

    def _pair_mesh(self, a: int, b: int):
        """(collision mesh, model vertex ids, None) of parts a and b, cached."""
        key = (a, b)
        if key not in self._meshes:
            s = self.solids
            ids = s.pair_vertices(a, b)
            self._meshes[key] = (self._collision_mesh(self._rest[ids], s.triangles[a],
                                                      s.triangles[b]), ids, None)
        return self._meshes[key]

    def _zone_mesh(self, k: int):
        """(collision mesh, model vertex ids, pull-back) of joined pair k's trimmed
        panels, cached; the pull-back maps the pair's (3n,) dofs to its trimmed
        corners'."""
        key = ("joined", k)
        if key not in self._meshes:
            z, s = self.zones, self.solids
            a, b = (int(p) for p in z.pairs[k])
            mesh = self._collision_mesh(z.rest[z.rows(k)], s.triangles[a], s.triangles[b])
            ids, weights = z.pair(k)
            self._meshes[key] = (mesh, ids, np.kron(weights, np.eye(3)))
        return self._meshes[key]

    @staticmethod
    def _collision_mesh(rest: np.ndarray, faces_a: np.ndarray, faces_b: np.ndarray):
        """ipctk's collision mesh of two prisms: rest (n, 3) their corners (a's
        first), faces_a/faces_b their triangles (local indices), each body only
        against the other."""
        ipctk = load_ipctk()
        n_a = int(faces_a.max()) + 1
        faces = np.vstack([faces_a, faces_b + n_a]).astype(np.int32)
        mesh = ipctk.CollisionMesh(np.asfortranarray(rest), ipctk.edges(faces), faces)
        mesh.can_collide = ipctk.make_vertex_patches_filter(
            np.repeat([0, 1], [n_a, len(rest) - n_a]).astype(np.int32))
        return mesh

    # -------------------------------------------------------- the barrier
    def state(self, x: np.ndarray, joined: bool = True) -> ContactState:
        """The contacts at positions x (N, 3); ``joined``: also between panels a crease
        joins (a strategy with exactly rigid panels; otherwise their hinge holds
        them)."""
        ipctk = load_ipctk()
        pairs, gaps, energy, terms, kinds = [], [], 0.0, [], []
        for joined, (a, b), mesh, ids, pull, local in self._terms_at(x, joined):
            dhat, potential = (self.dhat_joined if joined else self.dhat), self._potential[joined]
            collisions = ipctk.NormalCollisions()
            collisions.build(mesh, local, dhat)
            if not len(collisions):
                continue
            pairs.append((a, b))
            kinds.append(joined)
            gaps.append(np.sqrt(collisions.compute_minimum_distance(mesh, local)))
            energy += float(potential(collisions, mesh, local))
            terms.append((ids, collisions, mesh, local, potential, pull))
        pairs = np.array(pairs, dtype=np.int64).reshape(-1, 2)
        state = ContactState(pairs, np.array(gaps, dtype=float), energy, terms,
                             joined=np.array(kinds, dtype=bool), _obstacle_of=[-1] * len(terms))
        if self.obstacles is not None:
            found, pairs, gaps = self.obstacles.terms(x, self.dhat)
            for o, term in found:
                ids, collisions, mesh, local, potential, _ = term
                state.energy += float(potential(collisions, mesh, local))
                state._terms.append(term)
                state._obstacle_of.append(o)
            state.obstacle_pairs = np.array(pairs, dtype=np.int64).reshape(-1, 2)
            state.obstacle_gaps = np.array(gaps, dtype=float)
        return state

    def touching(self, state: ContactState) -> list:
        """[(key, (n,) model vertex ids)] of every barrier term at ``state``: a pair's two
        parts (key (a, b)), a part an obstacle presses (key (p,))."""
        s = self.solids
        return ([((int(a), int(b)), s.pair_vertices(int(a), int(b))) for a, b in state.pairs]
                + [((int(p),), s.part_vertices(int(p))) for p, _ in state.obstacle_pairs])

    @staticmethod
    def _term_gradients(state: ContactState):
        """Per barrier term at ``state``: (its obstacle or −1, model vertex ids (n,),
        ∂(κ b)/∂x on them (n, 3) mm⁴, pulled back to the model's vertices)."""
        for o, (ids, collisions, mesh, local, potential, pull) in zip(state._obstacle_of,
                                                                       state._terms):
            g = potential.gradient(collisions, mesh, local)
            yield o, ids, (g if pull is None else pull.T @ g).reshape(-1, 3)

    def gradient(self, state: ContactState) -> np.ndarray:
        """(N, 3) ∂(κ Σ b)/∂x at a state's positions, mm⁴."""
        out = np.zeros((self.n_vertices, 3))
        for _, ids, g in self._term_gradients(state):
            out[ids] += g
        return out

    def hessian_blocks(self, state: ContactState):
        """Each barrier term's (model vertex ids (n,), PSD-projected block of
        ∂²(κ Σ b)/∂x² over their dofs, (3n, 3n) sparse, mm³)."""
        ipctk = load_ipctk()
        for ids, collisions, mesh, local, potential, pull in state._terms:
            block = potential.hessian(collisions, mesh, local, ipctk.PSDProjectionMethod.CLAMP)
            if pull is not None:
                block = sp.coo_matrix(pull.T @ block.toarray() @ pull)
            yield ids, block

    def hessian(self, state: ContactState) -> sp.csr_matrix:
        """(3N, 3N) PSD-projected ∂²(κ Σ b)/∂x², mm³ (each pair's block clamped)."""
        rows, cols, vals = [], [], []
        for ids, block in self.hessian_blocks(state):
            block = block.tocoo()
            dof = (3 * ids[:, None] + np.arange(3)).ravel()
            rows.append(dof[block.row])
            cols.append(dof[block.col])
            vals.append(block.data)
        n = 3 * self.n_vertices
        if not rows:
            return sp.csr_matrix((n, n))
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))), shape=(n, n))

    # ------------------------------------------------------------- steps
    def free_fraction(self, x0: np.ndarray, x1: np.ndarray, joined: bool = True) -> float:
        """A share t ∈ [0, 1] of the step x0 → x1 that brings no two parts into
        contact; 1 where nothing comes near. x0 must be intersection-free.

        Unjoined pairs: the largest t for which the straight-line motion
        x0 → x0 + t (x1 − x0) is collision-free (additive CCD, rescaled by
        ``CCD_RESCALING``). Joined pairs turn about the hinge they share, whose
        chords cut across it, so a straight-line check would stop them where the
        hinge keeps their faces a hair apart; their trimmed geometry
        (:class:`~.solids.JoinedZones`) is checked at x1 instead (½ where it
        intersects): two panels a hinge joins cannot pass through each other
        without intersecting on the way, and a step is a small turn of that
        hinge. ``joined`` False leaves them out (a strategy
        whose panels are not exactly rigid: their hinge holds them)."""
        s = self.solids
        self.blocking = []
        if not s.n_parts:
            return 1.0
        lo0, hi0 = s.boxes(x0)
        lo1, hi1 = s.boxes(x1)
        pairs = s.pairs_near(np.minimum(lo0, lo1), np.maximum(hi0, hi1), 0.0)
        if len(pairs):
            pairs = pairs[s.gap_bounds(x0, pairs, later=x1) <= 0.0]
        ipctk = load_ipctk()
        fraction = 1.0
        for a, b in pairs:
            mesh, ids, _ = self._pair_mesh(int(a), int(b))
            t = ipctk.compute_collision_free_stepsize(
                mesh, np.asfortranarray(x0[ids]), np.asfortranarray(x1[ids]),
                narrow_phase_ccd=self._ccd)
            fraction = min(fraction, float(t))
            if t < 1.0:
                self.blocking.append((int(a), int(b)))
        if self.obstacles is not None:
            fraction = min(fraction, self.obstacles.free_fraction(x0, x1))
        if not joined:
            return fraction
        which, y = self._joined_near(x1, 0.0)
        for k in which:
            mesh, _, _ = self._zone_mesh(int(k))
            if ipctk.has_intersections(mesh, np.asfortranarray(y[self.zones.rows(int(k))])):
                self.blocking.append(tuple(int(p) for p in self.zones.pairs[k]))
                return min(fraction, 0.5)
        return fraction

    def overlapping(self, x: np.ndarray) -> np.ndarray:
        """(K, 2) part pairs, not left out, whose surfaces intersect at x (a check, not a
        step's work)."""
        ipctk = load_ipctk()
        found = []
        for a, b in self.candidates(x, 0.0):
            mesh, ids, _ = self._pair_mesh(int(a), int(b))
            if ipctk.has_intersections(mesh, np.asfortranarray(x[ids])):
                found.append((a, b))
        return np.array(found, dtype=np.int64).reshape(-1, 2)

    def obstacles_touching(self, x: np.ndarray) -> list:
        """[(part, obstacle)] intersecting or touching at x (empty without obstacles)."""
        return [] if self.obstacles is None else self.obstacles.touching(x)

    def obstacle_forces(self, state: ContactState) -> np.ndarray:
        """(n_obstacles, 3) force the parts press each obstacle with (Σ of the
        barrier's gradient on the parts' vertices of its terms), mm⁴."""
        n = 0 if self.obstacles is None else len(self.obstacles.obstacles)
        out = np.zeros((n, 3))
        for o, _, g in self._term_gradients(state):
            if o >= 0:
                out[o] += g.sum(axis=0)
        return out

    def forces(self, state: ContactState) -> np.ndarray:
        """(n_parts, 3) contact force on each part: −Σ of the barrier's gradient on its
        vertices, term by term (a vertex a strip shares with its panel counts for
        the part whose term it is), mm⁴."""
        out = np.zeros((self.solids.n_parts, 3))
        pairs, pressed = iter(state.pairs), iter(state.obstacle_pairs)
        for o, _, g in self._term_gradients(state):
            if o >= 0:
                out[next(pressed)[0]] -= g.sum(axis=0)
                continue
            a, b = (int(p) for p in next(pairs))
            n_a = len(self.solids.part_vertices(a))
            out[a] -= g[:n_a].sum(axis=0)
            out[b] -= g[n_a:].sum(axis=0)
        return out
