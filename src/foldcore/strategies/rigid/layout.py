"""The unknowns of the rigid-body step and where they sit.

Per free panel an incremental rotation ω_p (exponential map) and a shift t_p;
every vertex that belongs to no panel (hinge interiors) its position; per
hinge sub-strip an incremental rotation ω_e of its target; per *passive*
crease its bend angle, bounded to the interval its M/V assignment, floor and
max angle allow. :class:`UnknownLayout` holds which vertex rides on which
panel, how hinge-interior vertices are carried by their crease's two panels,
the column blocks of the unknowns and the fixed pattern of the normal matrix.
Units: mm, rad.
"""
from __future__ import annotations

import numpy as np

from ...errors import SimulationError
from . import normal


def mv_creases(pattern, stiffness: float) -> np.ndarray:
    """(C,) M/V creases between two faces: the ones with an M/V side row (none when
    the rows' ``stiffness`` is 0)."""
    kinds = pattern.assignments
    crease = np.flatnonzero(((kinds == "M") | (kinds == "V")) & (pattern.edge_faces[:, 1] >= 0))
    return crease if stiffness > 0 else crease[:0]


class UnknownLayout:
    """Ownership, carriers and column layout of one mesh's rigid-body unknowns.

    Parameters
    ----------
    model : foldcore.model.Model
        A mesh of rigid panels and bending hinges of 8 vertices each.
    mv_stiffness : float
        Weight factor of the M/V side rows (0: none; their panels' blocks are
        part of the normal matrix's pattern).

    Attributes
    ----------
    owner : (N,) int
        Panel of each vertex (−1: a hinge-interior vertex, "free").
    on_panel, panel_of : (n,) int
        Vertices on a panel and their panel.
    free : (F,) int
        Hinge-interior vertices.
    body : (n, 3) float
        Panel vertices in their panel's rest frame (about its centroid), mm.
    ids : (S, 8) int
        Each hinge sub-strip's vertices.
    k_strip : (S,) float
        Sub-strips of each strip's crease.
    strip_side : (S, 2) int
        The two panels of each strip's crease.
    """

    def __init__(self, model, mv_stiffness: float):
        mesh, pattern = model.mesh, model.pattern
        self.n_vertices = mesh.n_vertices
        self._init_panels(mesh.groups["rigid_panel"], mesh)
        self._init_strips(model.hinges, mesh)
        self._init_carriers(mesh, pattern)
        crease = mv_creases(pattern, mv_stiffness)
        self.mv_left = mesh.panel_of_face[pattern.edge_faces[crease, 0]]
        self.mv_right = mesh.panel_of_face[pattern.edge_faces[crease, 1]]
        self.passive = None  # (S,) bool of the current layout (set_passive)
        self.pinned = False
        self.ready = False  # the column blocks exist (build_columns)
        self.version = 0  # patterns of the normal matrix built so far (a factor's key)
        #: {pair key: model vertex ids its barrier moves} of the contacts in the pattern
        self.contacts: dict = {}

    # ----------------------------------------------------------- structure
    def _init_panels(self, panels, mesh) -> None:
        owner = np.full(mesh.n_vertices, -1, dtype=np.int64)
        for p in range(len(panels)):
            ids = panels.indices[panels.slots(p)]
            if (owner[ids] >= 0).any():
                raise SimulationError(f"solver 'rigid': panel {p} shares vertices with panel "
                                      f"{owner[ids].max()}; panels must be separate bodies")
            owner[ids] = p
        self.panels = panels
        self.n_panels = len(panels)
        self.owner = owner
        self.on_panel = np.flatnonzero(owner >= 0)
        self.panel_of = owner[self.on_panel]  # (N,) the panel of each panel vertex
        self.free = np.flatnonzero(owner < 0)
        rest = mesh.rest_positions
        centroid = np.zeros((len(panels), 3))
        np.add.at(centroid, owner[self.on_panel], rest[self.on_panel])
        centroid /= np.bincount(owner[self.on_panel], minlength=len(panels))[:, None]
        self.body = rest[self.on_panel] - centroid[owner[self.on_panel]]

    def _init_strips(self, hinges, mesh) -> None:
        if hinges is None:
            raise SimulationError("solver 'rigid': the mesh has no hinges to fold")
        g = hinges.group
        if not np.all(np.diff(g.indptr) == 8):
            raise SimulationError("solver 'rigid': every hinge sub-strip must have 8 vertices")
        self.hinges = hinges
        slots = np.bincount(g.indices, minlength=mesh.n_vertices)[self.on_panel]
        p = self.owner[self.on_panel]
        jointless = np.bincount(p, weights=slots, minlength=self.n_panels) == 0
        #: (n,) weight of each panel vertex in the panel's shift: its strip slots
        self.joint_weight = np.where(jointless[p], 1.0, slots.astype(float))
        self.ids = g.indices.reshape(-1, 8)
        self.k_strip = mesh.subdivisions[g.source].astype(float)

    def _init_carriers(self, mesh, pattern) -> None:
        """Blend weights that carry each free (hinge-interior) vertex with its two panels.

        A free vertex at fraction f of its hinge's width (0 at the left panel,
        1 at the right) follows (1 − f)·(left panel's motion) + f·(right
        panel's) plus its own displacement, so a large panel rotation moves the
        hinge with it instead of along a straight line."""
        rest = mesh.rest_positions
        free_index = np.full(mesh.n_vertices, -1, dtype=np.int64)
        free_index[self.free] = np.arange(len(self.free))
        vert, panel, weight = [], [], []
        self.strip_side = np.zeros((len(self.ids), 2), dtype=np.int64)  # crease's panels
        side_weight = np.zeros((len(self.free), 2))  # each free vertex's blend weights
        for e, strips in mesh.strips_of_crease.items():
            ids = np.unique(self.ids[strips])
            side = [mesh.panel_of_face[f] for f in pattern.edge_faces[e]]
            self.strip_side[strips] = side
            inner = ids[free_index[ids] >= 0]
            dist = [np.linalg.norm(rest[inner, None, :2] - rest[None, ids[self.owner[ids] == p], :2],
                                   axis=2).min(axis=1) for p in side]
            f = dist[0] / (dist[0] + dist[1])
            vert += [inner, inner]
            panel += [np.full(len(inner), side[0]), np.full(len(inner), side[1])]
            weight += [1.0 - f, f]
            side_weight[free_index[inner]] = np.column_stack([1.0 - f, f])
        self.carry_vert = np.concatenate(vert) if vert else np.zeros(0, dtype=np.int64)
        self.carry_panel = np.concatenate(panel) if panel else np.zeros(0, dtype=np.int64)
        self.carry_weight = np.concatenate(weight) if weight else np.zeros(0)
        self.carry_slot = free_index[self.carry_vert]
        self._init_strip_motion(free_index, side_weight)

    def _init_strip_motion(self, free_index, side_weight) -> None:
        """Per strip vertex, the weight of each of its crease's two panels' motions
        (S, 8, 2) and its hinge-interior index (S, 8) (−1 on a panel): what
        :mod:`.normal` builds the strip rows from."""
        owner = self.owner[self.ids]
        alpha = np.stack([(owner == self.strip_side[:, b, None]).astype(float)
                          for b in range(2)], axis=2)
        stray = (owner >= 0) & (alpha.sum(axis=2) == 0)
        if stray.any():
            raise SimulationError(f"solver 'rigid': hinge sub-strip "
                                  f"{int(np.flatnonzero(stray.any(axis=1))[0])} touches a "
                                  "panel that is not one of its crease's two")
        self.strip_free = free_index[self.ids]
        inner = self.strip_free >= 0
        alpha[inner] = side_weight[self.strip_free[inner]]
        self.strip_alpha = alpha
        self._crease_rounds()

    def _crease_rounds(self) -> None:
        """Creases (strips grouped by source crease, CSR) in rounds of creases that share
        no panel (greedy colouring), so each round assembles in parallel."""
        source = self.hinges.group.source
        order = np.argsort(source, kind="stable")
        creases, first = np.unique(source[order], return_index=True)
        sides = self.strip_side[order[first]]
        used: dict = {}  # panel → colours of its creases so far
        colour = np.zeros(len(creases), dtype=np.int64)
        for c, (left, right) in enumerate(sides):
            taken = used.setdefault(left, set()) | used.setdefault(right, set())
            colour[c] = next(k for k in range(len(taken) + 1) if k not in taken)
            used[left].add(colour[c])
            used[right].add(colour[c])
        by_colour = np.argsort(colour, kind="stable")
        bounds = np.append(first, len(order))
        sizes = np.diff(bounds)[by_colour]
        self.crease_ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self.crease_strips = np.concatenate([order[bounds[c]:bounds[c + 1]] for c in by_colour]) \
            .astype(np.int64)
        self.rounds = np.searchsorted(colour[by_colour], np.arange(colour.max() + 2)) \
            .astype(np.int64)

    # ------------------------------------------------------- passive creases
    def set_passive(self, passive: np.ndarray, pinned: bool) -> None:
        """The passive creases' angle unknowns (``passive`` (S,) bool per strip) and
        whether position targets hold the rigid motion (``pinned``); the column
        blocks follow at the next :meth:`build_columns` (a coarse twin's hand-over
        may end a run without a step of this layout, and the columns and pattern
        are a large mesh's peak memory)."""
        self.passive_ids = np.flatnonzero(passive)
        src = self.hinges.group.source[self.passive_ids]
        _, self.passive_of = np.unique(src, return_inverse=True)
        self.n_folds = int(self.passive_of.max()) + 1 if len(src) else 0
        self.passive = passive.copy()
        self.pinned = pinned
        self.ready = False

    @property
    def laid_out(self) -> bool:
        """Whether the passive creases' unknowns exist (set by the first step)."""
        return self.passive is not None

    def fold_edges(self) -> np.ndarray:
        """(n_folds,) pattern edge of each passive crease's angle unknown."""
        edges = np.zeros(self.n_folds, dtype=np.int64)
        edges[self.passive_of] = self.hinges.group.source[self.passive_ids]
        return edges

    def folds(self, phi: np.ndarray) -> np.ndarray:
        """(n_folds,) total bend angle of each passive crease at strip angles ``phi``, rad."""
        return np.bincount(self.passive_of, weights=phi[self.passive_ids],
                           minlength=self.n_folds)

    def set_folds(self, folds: np.ndarray, phi: np.ndarray) -> None:
        """Spread each passive crease's angle evenly over its sub-strips (one arc)."""
        phi[self.passive_ids] = folds[self.passive_of] / self.k_strip[self.passive_ids]

    # -------------------------------------------------------------- columns
    def build_columns(self) -> None:
        """Column blocks of the unknowns (panels, free vertices, strip rotations,
        angles), the position map's pattern and the normal matrix's pattern; once
        per layout."""
        if self.ready:
            return
        fixed = -1
        if not self.pinned:  # no pins: one panel holds the rigid motion
            fixed = int(self.owner[0]) if self.owner[0] >= 0 else 0
        self.panel_col = np.full(self.n_panels, -1, dtype=np.int64)
        moving = np.flatnonzero(np.arange(self.n_panels) != fixed)
        self.panel_col[moving] = 6 * np.arange(len(moving))
        self.free_col = 6 * len(moving) + 3 * np.arange(len(self.free))
        self.rot_col = self.free_col[-1] + 3 if len(self.free) else 6 * len(moving)
        self.phi_col = self.rot_col + 3 * len(self.ids)
        self.n_unknowns = self.phi_col + self.n_folds
        self._map_pattern()
        self._strip_layout()
        self._normal_pattern()
        self.ready = True

    def _strip_layout(self) -> None:
        """Local columns of each strip for :mod:`.normal`: its crease's moving panels
        (6 each), its hinge-interior vertices (3 each), its rotation (3), its crease's
        angle (1, passive creases only)."""
        s = len(self.ids)
        pcol = self.panel_col[self.strip_side]  # (S, 2)
        moving = pcol >= 0
        # blocks in increasing global column (normal's scatter walks columns in order)
        right_first = moving.all(axis=1) & (pcol[:, 1] < pcol[:, 0])
        first = np.where(right_first, 6 * moving[:, 1], 0)
        self.off_panel = np.where(moving, np.column_stack([first, 6 * (moving[:, 0] & ~right_first)]),
                                  -1).astype(np.int64)
        base = 6 * moving.sum(axis=1)
        inner = self.strip_free >= 0
        key = np.where(inner, self.strip_free, -1)
        rank = (inner[:, None, :] & (key[:, None, :] < key[:, :, None])).sum(axis=2)
        self.own_off = np.where(inner, base[:, None] + 3 * rank, -1).astype(np.int64)
        self.off_w = (base + 3 * inner.sum(axis=1)).astype(np.int64)
        fold_of = np.full(s, -1, dtype=np.int64)
        fold_of[self.passive_ids] = self.passive_of
        self.off_phi = np.where(fold_of >= 0, self.off_w + 3, -1).astype(np.int64)
        self.n_loc = (self.off_w + 3 + (fold_of >= 0)).astype(np.int64)
        cols = np.full((s, normal.MAX_LOCAL), -1, dtype=np.int64)
        kind = np.full((s, normal.MAX_LOCAL), -1, dtype=np.int64)
        rows = np.arange(s)
        for b in range(2):
            on = moving[:, b]
            for d in range(6):
                cols[rows[on], self.off_panel[on, b] + d] = pcol[on, b] + d
                if d >= 3:
                    kind[rows[on], self.off_panel[on, b] + d] = normal.TRANSLATION + d - 3
        strip, k = np.nonzero(inner)
        for d in range(3):
            cols[strip, self.own_off[strip, k] + d] = self.free_col[self.strip_free[strip, k]] + d
            kind[strip, self.own_off[strip, k] + d] = normal.TRANSLATION + d
            cols[rows, self.off_w + d] = self.rot_col + 3 * rows + d
            kind[rows, self.off_w + d] = normal.ROTATION + d
        on = fold_of >= 0
        cols[rows[on], self.off_phi[on]] = self.phi_col + fold_of[on]
        self.loc_cols, self.loc_kind = cols, kind

    def add_contacts(self, touching) -> bool:
        """Make room in the normal matrix for contacts that act: ``touching``, [(key,
        (n,) model vertex ids its barrier moves)] (``ContactModel.touching``); True
        when the pattern grew (a new symbolic analysis follows). Contacts stay once
        added: one that opens and closes again costs one analysis."""
        new = {key: ids for key, ids in touching if key not in self.contacts}
        if not new:
            return False
        self.contacts.update(new)
        if self.ready:
            self._normal_pattern()
        return True

    def columns_of(self, ids: np.ndarray) -> np.ndarray:
        """Sorted columns of the unknowns that move the vertices ``ids`` (P's nonzero
        columns in their rows): the moving panels they ride on or that carry them,
        6 each, and a hinge-interior vertex's own 3."""
        ids = np.asarray(ids, dtype=np.int64)
        owner = self.owner[ids]
        free = ids[owner < 0]
        panels = np.union1d(owner[owner >= 0], self.carry_panel[np.isin(self.carry_vert, free)])
        panel_cols = self.panel_col[panels.astype(np.int64)]
        panel_cols = panel_cols[panel_cols >= 0]
        own = self.free_col[np.searchsorted(self.free, free)]
        return np.sort(np.concatenate([(panel_cols[:, None] + np.arange(6)).ravel(),
                                       (own[:, None] + np.arange(3)).ravel()]))

    def _contact_blocks(self) -> list:
        """Blocks (≤ ``normal.MAX_LOCAL`` columns each, increasing) that hold every
        pair of the columns each contact moves: those columns in runs of at most
        half that width, and a block per two runs (a panel pair's 12 columns are
        one block)."""
        half = normal.MAX_LOCAL // 2
        out = []
        for ids in self.contacts.values():
            cols = self.columns_of(ids)
            runs = [cols[i:i + half] for i in range(0, len(cols), half)]
            out += [np.concatenate([runs[i], runs[j]]) if i != j else runs[i]
                    for i in range(len(runs)) for j in range(i, len(runs))]
        return out

    def _normal_pattern(self) -> None:
        """Fixed CSC pattern of JᵀJ (:mod:`.normal`'s docstring): indptr, indices and
        the slot of each diagonal entry. Blocks beside the strips': each moving
        panel's 6 × 6 block (position targets), each M/V crease's two panel
        rotations, the columns of each contact (:meth:`_contact_blocks`); every
        column's diagonal comes first in its column."""
        n = self.n_unknowns
        width = normal.MAX_LOCAL
        panel = self.panel_col[self.panel_col >= 0]
        left, right = self.panel_col[self.mv_left], self.panel_col[self.mv_right]
        both = (left >= 0) & (right >= 0)
        contacts = self._contact_blocks()
        blocks = [panel[:, None] + np.arange(6),
                  np.column_stack([left[both, None] + np.arange(3),
                                   right[both, None] + np.arange(3)]),
                  np.full((len(contacts), width), -1, dtype=np.int64)]
        for row, block in zip(blocks[2], contacts):
            row[:len(block)] = block
        cols, n_loc, kind = [self.loc_cols], [self.n_loc], [self.loc_kind]
        for block, size in zip(blocks, [np.full(len(blocks[0]), 6), np.full(len(blocks[1]), 6),
                                        np.array([len(c) for c in contacts])]):
            padded = np.full((len(block), width), -1, dtype=np.int64)
            padded[:, :block.shape[1]] = block
            cols.append(padded)
            n_loc.append(np.asarray(size, dtype=np.int64))
            kind.append(np.full((len(block), width), -1, dtype=np.int64))
        indptr, indices = normal.pattern_csc(
            np.concatenate(n_loc), np.concatenate(cols), np.concatenate(kind), n)
        # 32-bit indices, as CHOLMOD's int interface and SciPy take them: no copy per step
        index = np.int32 if indptr[-1] < np.iinfo(np.int32).max else np.int64
        self.csc_indptr, self.csc_indices = indptr.astype(index), indices.astype(index)
        self.diag_slot = self.csc_indptr[:-1].astype(np.int64)  # first in each column
        self.version += 1

    def _map_pattern(self) -> None:
        """COO pattern of P = ∂x/∂(panel, free-vertex unknowns), (3N, n_q): every vertex
        moved by a panel (its own, or the two carrying a free vertex, with blend
        weights) gets weight·[−[a]× | I] in that panel's columns (a = x − c_p, filled
        per linearisation); free vertices also get I in their own columns."""
        verts = np.concatenate([self.on_panel, self.carry_vert])
        panels = np.concatenate([self.owner[self.on_panel], self.carry_panel])
        weight = np.concatenate([np.ones(len(self.on_panel)), self.carry_weight])
        moving = self.panel_col[panels] >= 0
        self.m_vert, self.m_panel, self.m_weight = verts[moving], panels[moving], weight[moving]
        col0 = self.panel_col[self.m_panel]
        rows, cols = [], []
        for d in range(3):
            for c in range(3):  # −[a]× block, values per iteration
                rows.append(3 * self.m_vert + d)
                cols.append(col0 + c)
            rows.append(3 * self.m_vert + d)  # shift
            cols.append(col0 + 3 + d)
        for d in range(3):
            rows.append(3 * self.free + d)
            cols.append(self.free_col + d)
        self.p_rows = np.concatenate(rows)
        self.p_cols = np.concatenate(cols)
        self.n_q = self.rot_col
