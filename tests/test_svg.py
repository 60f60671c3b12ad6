"""SVG crease patterns in Origami Simulator's colours."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from foldcore.errors import PatternError, PatternWarning
from foldcore.io import Reading, read
from foldcore.io.svg import CURVE_DEPTH, CURVE_SAG_PX, MM_PER_PX, SNAP_PX

REAL = "tests/data/real/"


def svg(body: str, size: int = 100) -> str:
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}px" height="{size}px" '
            f'viewBox="0 0 {size} {size}">{body}</svg>')


SQUARE = '<rect x="0" y="0" width="100" height="100" fill="none" stroke="#000"/>'


def read_text(tmp_path, text: str, reading=None):
    path = tmp_path / "p.svg"
    path.write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pattern = read(path, reading=reading)
    return pattern, [str(w.message) for w in caught if w.category is PatternWarning]


def crease_set(pattern) -> dict:
    """{(kind, target): count} over the creases."""
    out = {}
    for kind, angle in zip(pattern.assignments, pattern.fold_angles):
        if kind != "B":
            key = (str(kind), None if np.isnan(angle) else round(float(angle), 6))
            out[key] = out.get(key, 0) + 1
    return out


def test_origami_simulators_miura_reads_as_its_182_nodes_and_287_creases():
    """The count Origami Simulator shows for its own Tessellations/miura-ori.svg."""
    pattern = read(REAL + "miura-ori.svg")
    assert len(pattern.vertices) == 182
    assert crease_set(pattern) == {("M", -180.0): 137, ("V", 180.0): 150}


def test_opacity_is_the_target_angle_as_a_share_of_180():
    pattern = read(REAL + "waterbombBase.svg")  # valleys at opacity 0.5
    assert crease_set(pattern) == {("M", -180.0): 4, ("V", 90.0): 4}


def test_colours_styles_and_transforms_as_a_browser_computes_them(tmp_path):
    body = SQUARE + (
        '<style>.v { stroke: blue; stroke-opacity: 0.25 }</style>'
        '<line x1="50" y1="0" x2="50" y2="100" class="v"/>'
        '<g transform="translate(0 50)"><path d="M0 0 H100" style="stroke:rgb(255,0,0)"/></g>')
    pattern, _ = read_text(tmp_path, body and svg(body))
    assert crease_set(pattern) == {("V", 45.0): 2, ("M", -180.0): 2}  # crossing: noded
    assert len(pattern.vertices) == 9


def test_lengths_are_css_pixels_and_the_drawing_is_not_mirrored(tmp_path):
    body = SQUARE + '<line x1="0" y1="0" x2="100" y2="100" stroke="#ff0000"/>'
    pattern, _ = read_text(tmp_path, svg(body))
    v = pattern.vertices
    assert np.ptp(v, axis=0) == pytest.approx([100 * MM_PER_PX] * 2)
    top_left = np.argmin(v[:, 0] - v[:, 1])  # SVG (0, 0): smallest x, largest y
    assert v[top_left] == pytest.approx([0.0, 0.0])
    assert read_text(tmp_path, svg(body), Reading(size=200.0))[0].vertices.max() \
        == pytest.approx(200.0)


def test_a_t_join_drawn_short_is_snapped_and_overlaps_are_one_edge(tmp_path):
    body = SQUARE + ('<line x1="50" y1="0.8" x2="50" y2="100" stroke="#00f"/>'  # 0.8 px short
                     '<line x1="50" y1="50" x2="50" y2="100" stroke="#00f"/>')  # overlaps it
    pattern, _ = read_text(tmp_path, svg(body))
    assert crease_set(pattern) == {("V", 180.0): 2}  # split where the second one starts
    assert len(pattern.vertices) == 7  # 4 corners, both T-joins, (50, 50)


def test_a_curved_crease_is_read_as_a_polyline_within_its_tolerance(tmp_path):
    """A quadratic Bézier valley: its pieces' ends lie on the curve (up to the
    reader's snapping of joints, SNAP_PX), the curve within CURVE_SAG_PX of the
    pieces (plus that snapping), and one note says how many pieces."""
    body = SQUARE + '<path d="M50 0 Q90 50 50 100" stroke="#00f" fill="none"/>'
    pattern, notes = read_text(tmp_path, svg(body))
    creases = [e for e, k in enumerate(pattern.assignments) if k == "V"]
    pieces = len(creases)
    assert 2 <= pieces <= 2 ** CURVE_DEPTH
    assert any(f"1 curved segments read as {pieces} straight pieces" in n for n in notes)
    px = pattern.vertices[np.unique(pattern.edges[creases])] / MM_PER_PX * [1, -1]
    t = np.linspace(0, 1, 2001)[:, None]   # the curve, densely
    curve = (1 - t) ** 2 * [50, 0] + 2 * t * (1 - t) * [90, 50] + t ** 2 * [50, 100]
    nearest = np.min(np.linalg.norm(px[:, None, :] - curve[None], axis=2), axis=1)
    assert nearest.max() < SNAP_PX  # on the curve, but for the reader's snapping of joints
    # the curve within CURVE_SAG_PX of the polyline: distance of samples to the pieces
    ordered = px[np.argsort(px[:, 1])]
    seg_a, seg_b = ordered[:-1], ordered[1:]
    d = seg_b - seg_a
    u = np.clip(np.einsum("kij,ij->ki", curve[:, None, :] - seg_a[None], d)
                / np.einsum("ij,ij->i", d, d), 0, 1)
    gap = np.linalg.norm(curve[:, None, :] - (seg_a + u[..., None] * d), axis=2).min(axis=1)
    assert gap.max() <= CURVE_SAG_PX + nearest.max()  # the sag, and the joints' snapping


def test_lines_whose_type_contradicts_their_sides_are_read_as_origami_simulator_reads_them(
        tmp_path):
    """A red line along the sheet's edge has no face to fold against: boundary. A
    black line across the sheet has faces on both sides: a free hinge (U)."""
    body = ('<polyline points="100,0 100,100 0,100 0,0" fill="none" stroke="#000"/>'
            '<line x1="0" y1="0" x2="100" y2="0" stroke="#f00"/>'        # the top edge
            '<line x1="50" y1="0" x2="50" y2="100" stroke="#000"/>'      # across
            '<line x1="0" y1="50" x2="50" y2="50" stroke="#00f"/>')
    pattern, notes = read_text(tmp_path, svg(body))
    kinds = dict(zip(map(tuple, np.round(pattern.vertices[pattern.edges].mean(axis=1)
                                         / MM_PER_PX).astype(int).tolist()),
                     pattern.assignments))
    assert kinds[(25, 0)] == kinds[(75, 0)] == "B"          # the red line: boundary
    assert kinds[(50, -25)] == kinds[(50, -75)] == "U"      # the black line: free hinge
    assert kinds[(25, -50)] == "V"
    assert any("read as boundary, as Origami Simulator reads them" in n for n in notes)
    assert any("read as free hinges (U)" in n for n in notes)


def test_lines_drawn_over_each_other_read_as_origami_simulator_keeps_them(tmp_path):
    """Two crease types on one line: Origami Simulator keeps the type its reader lists
    first (B, M, V, F, U), whatever the file order; two angles of one type, the first
    in the file. Said once, with the count and what was kept over what."""
    valley_then_mountain = ('<line x1="50" y1="0" x2="50" y2="100" stroke="#00f"/>'
                            '<line x1="50" y1="0" x2="50" y2="100" stroke="#f00"/>')
    pattern, said = read_text(tmp_path, svg(SQUARE + valley_then_mountain))
    assert crease_set(pattern) == {("M", -180.0): 1}
    (message,) = [m for m in said if "Origami Simulator's order" in m]
    assert "1 pieces" in message and "M over V" in message
    half_then_full = ('<line x1="50" y1="0" x2="50" y2="100" stroke="#f00" opacity="0.5"/>'
                      '<line x1="50" y1="0" x2="50" y2="100" stroke="#f00"/>')
    pattern, said = read_text(tmp_path, svg(SQUARE + half_then_full))
    assert crease_set(pattern) == {("M", -90.0): 1}
    assert any("M over M" in m for m in said)


def test_a_green_line_is_a_cut_that_splits_the_sheet_said_once(tmp_path):
    """Origami Simulator's green line cuts the sheet: across the square, two pieces."""
    pattern, said = read_text(tmp_path, svg(SQUARE + '<line x1="50" y1="0" x2="50" '
                                            'y2="100" stroke="#0f0"/>'))
    assert pattern.pieces == 2 and set(pattern.assignments) == {"B"}
    assert len(pattern.copied_from) == 2
    assert [m for m in said if "cut edge" in m] == [
        f"{tmp_path / 'p.svg'}: 1 cut edge ('C'): the sheet is split along it, each side a "
        "boundary edge (2 vertex copies along the cuts)"]


def test_lines_drawn_outside_the_sheet_are_left_out_said_once(tmp_path):
    """A crease and a boundary stub sticking out of the square, and a crease ending
    inside it: the stubs outside fold nothing and are left out; the inner crease stays
    (a dangling crease)."""
    body = SQUARE + ('<line x1="100" y1="50" x2="130" y2="50" stroke="#f00"/>'
                     '<line x1="0" y1="20" x2="-20" y2="20" stroke="#000"/>'
                     '<line x1="0" y1="50" x2="50" y2="50" stroke="#00f"/>')
    pattern, said = read_text(tmp_path, svg(body, size=140))
    grid = 1.5 * MM_PER_PX  # the snap distance of a 150 px drawing (1 % of it)
    assert np.ptp(pattern.vertices[:, 0]) == pytest.approx(100 * MM_PER_PX, abs=grid)
    assert crease_set(pattern) == {("V", 180.0): 1} and len(pattern.dangling) == 1
    assert len([m for m in said if "sheet on neither side" in m and "2 lines" in m]) == 1


def test_a_straight_bezier_is_a_line_and_other_colours_are_ignored_said_once(tmp_path):
    body = SQUARE + ('<path d="M50 0 C50 30 50 60 50 100" stroke="#f00" fill="none"/>'
                     '<line x1="0" y1="50" x2="100" y2="50" stroke="#888"/>'
                     '<line x1="0" y1="20" x2="100" y2="20" stroke="#888"/>')
    pattern, said = read_text(tmp_path, svg(body))
    assert crease_set(pattern) == {("M", -180.0): 1}
    (message,) = said
    assert "2 shapes" in message and "#888888" in message


def test_not_an_svg_is_one_line(tmp_path):
    with pytest.raises(PatternError) as info:
        read_text(tmp_path, "<svg><line")
    assert "p.svg" in str(info.value) and "\n" not in str(info.value)


def test_a_t_join_next_to_a_crossing_is_not_an_overlap(tmp_path):
    """Origami Simulator's traditionalCrane.svg has a valley starting 2.4 px from a
    mountain it crosses: it is snapped onto it, and the short piece left near the
    crossing lies near both lines, yet is no overlap of different crease types. A
    piece is typed by the segment it lies along (direction within PARALLEL); the
    small case checks a snapped T-join's pieces."""
    body = ('<rect x="0" y="0" width="400" height="400" fill="none" stroke="#000"/>'
            '<line x1="0" y1="0" x2="400" y2="400" stroke="#f00"/>'
            '<line x1="202.4" y1="200" x2="400" y2="150" stroke="#00f"/>')  # 1.7 px off
    pattern, _ = read_text(tmp_path, svg(body, size=400))
    assert crease_set(pattern) == {("M", -180.0): 2, ("V", 180.0): 1}
    crane = read(REAL + "traditionalCrane.svg")
    assert (crane.assignments == "M").any() and (crane.assignments == "V").any()


@pytest.mark.parametrize("second", [206.25, 207.9, 212.0])
def test_a_short_piece_between_two_creases_keeps_its_own_type(tmp_path, second):
    """A mountain–valley–mountain line crossing two valleys 6 … 12 px apart (a maze's
    short valley step): on the 3 px grid the short valley piece comes within reach
    of the collinear mountain that ends at it, which only meets it at an end; it
    stays a valley, and no overlap is reported (it was read as a mountain "drawn
    over" it, and Origami Simulator's maze lost a few hundred valleys so)."""
    body = ('<rect x="0" y="0" width="400" height="400" fill="none" stroke="#000"/>'
            '<line x1="200" y1="0" x2="200" y2="400" stroke="#00f"/>'
            f'<line x1="{second}" y1="0" x2="{second}" y2="400" stroke="#00f"/>'
            '<line x1="0" y1="200" x2="200" y2="200" stroke="#f00"/>'
            f'<line x1="200" y1="200" x2="{second}" y2="200" stroke="#00f"/>'
            f'<line x1="{second}" y1="200" x2="400" y2="200" stroke="#f00"/>')
    pattern, said = read_text(tmp_path, svg(body, size=400))
    assert not any("drawn as two crease types" in line for line in said)
    across = sorted((float(pattern.vertices[a, 0] + pattern.vertices[b, 0]), str(kind))
                    for (a, b), kind in zip(pattern.edges, pattern.assignments)
                    if kind != "B" and abs(pattern.vertices[a, 1] - pattern.vertices[b, 1]) < 1e-9)
    assert [kind for _, kind in across] == ["M", "V", "M"], across


CREASE = '<line x1="50" y1="0" x2="50" y2="100" stroke="#f00"/>'


@pytest.mark.parametrize("text, needles", [
    ('<html xmlns="http://www.w3.org/2000/svg"><body>' + SQUARE + CREASE + '</body></html>',
     ["root element is <html>"]),
    (svg(SQUARE + '<line x1="-1e308" y1="0" x2="50" y2="100" stroke="#f00"/>'),
     ["line 1", "outside the accepted"]),
    (svg(SQUARE + '<g transform="translate(1e308)">' + CREASE + '</g>'),
     ["line 1", "outside the accepted"]),
    (svg(SQUARE + '<line x1="1e309" y1="0" x2="50" y2="100" stroke="#f00"/>'),
     ["line 1", "x1='1e309'", "not a finite number"]),
    (svg(SQUARE + '<line x1="nan" y1="0" x2="50" y2="100" stroke="#f00"/>'),
     ["line 1", "x1='nan'"]),
    (svg(SQUARE + '<polyline points="50,0 nan,100" stroke="#f00" fill="none"/>'),
     ["polyline 1", "'nan'"]),
    (svg(SQUARE + '<line x1="50" y1="0" x2="50" y2="100" stroke="#f00" opacity="nan"/>'),
     ["line 1", "opacity=nan"]),
    (svg(SQUARE + '<g transform="scale(0)">' + CREASE + '</g>'),
     ["line 1", "singular"]),
    (svg(SQUARE + '<g>' * 150 + CREASE + '</g>' * 150), ["nested more than 100 deep"]),
    ('<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]>'
     + svg(SQUARE + CREASE + '<desc>&b;</desc>'), ["entities"]),
    ('<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY x SYSTEM "file:///etc/passwd">]>'
     + svg(SQUARE + CREASE + '<desc>&x;</desc>'), ["entities"]),
    ('<svg xmlns="http://www.w3.org/2000/svg" width="2em" height="100px" '
     'viewBox="0 0 100 100">' + SQUARE + CREASE + '</svg>', ["not a readable SVG"]),
])
def test_hostile_drawings_are_refused_in_one_line_naming_the_element(tmp_path, text, needles):
    """Numbers outside the arithmetic's range, values svgelements would read as 0, a
    singular transform (its crease would vanish), deep nesting and entities: each is
    one line naming the file and what is wrong, nothing read silently otherwise."""
    with pytest.raises(PatternError) as info:
        read_text(tmp_path, text)
    message = str(info.value)
    assert "p.svg" in message and "\n" not in message
    for needle in needles:
        assert needle in message, message


def test_many_lines_through_one_place_are_refused_before_the_work(tmp_path):
    """400 lines through the sheet's centre meet 80 000 times at one place: counted
    before noding (which took minutes and gigabytes) and refused."""
    lines = "".join(f'<line x1="{i / 4}" y1="0" x2="{100 - i / 4}" y2="100" stroke="#f00"/>'
                    for i in range(400))
    with pytest.raises(PatternError, match="too many lines through one place|meet or cross"):
        read_text(tmp_path, svg(SQUARE + lines))


def test_a_comment_is_skipped_in_time_linear_in_its_size(tmp_path):
    """A 4 MB comment (svgelements' own parse of comments grows faster than their
    size): screened out before it, so the pattern reads as without it."""
    plain, _ = read_text(tmp_path, svg(SQUARE + CREASE))
    commented, _ = read_text(tmp_path, svg(SQUARE + CREASE + "<!--" + "x" * 4_000_000 + "-->"))
    assert crease_set(commented) == crease_set(plain) == {("M", -180.0): 1}


def test_a_rotated_rect_is_read_rotated(tmp_path):
    """A rect's transform that rotates it is applied (a rect cannot take it into its
    own x, y, width, height): the square 40 … 60 px turned by 45° about its centre
    has its corners on the axes through the centre, 10√2 px from it."""
    from foldcore.io.svg import _strokes

    path = tmp_path / "p.svg"
    path.write_text(svg('<rect x="40" y="40" width="20" height="20" fill="none" '
                        'stroke="#00f" transform="rotate(45 50 50)"/>'))
    segments, kinds, _, _, _ = _strokes(str(path))
    corners = segments[:, 0] - 50.0
    assert len(segments) == 4 and set(kinds) == {"V"}
    np.testing.assert_allclose(np.abs(corners).max(axis=1), 10 * 2 ** 0.5, rtol=1e-12)
    np.testing.assert_allclose(np.abs(corners).min(axis=1), 0.0, atol=1e-9)


def test_vertices_are_numbered_as_origami_simulator_reads_the_drawing(tmp_path):
    """Origami Simulator reads the border lines first, then mountains, valleys, cuts,
    facets and free hinges, each kind as paths, lines, rects, polygons, polylines: a
    valley drawn before the border still numbers its vertices after the border's (the
    numbering decides the diagonal of a square face)."""
    body = ('<line x1="50" y1="100" x2="50" y2="0" stroke="#00f"/>'
            '<polyline points="0,100 0,0" fill="none" stroke="#000"/>'
            '<line x1="0" y1="0" x2="100" y2="0" stroke="#000"/>'
            '<path d="M100 0 L100 100 L0 100" fill="none" stroke="#000"/>')
    pattern, _ = read_text(tmp_path, svg(body))
    px = np.round(pattern.vertices / MM_PER_PX * [1, -1], 6).tolist()
    assert px == [[100, 0], [100, 100], [0, 100], [0, 0], [50, 100], [50, 0]]


def test_a_square_face_is_cut_along_its_shorter_diagonal_as_drawn(tmp_path):
    """Origami Simulator compares a quadrilateral's diagonals on the points as drawn;
    foldcore's reader merges points onto a grid (1 px for a 100 px drawing), where
    this square's corner drawn at (0.3, 100) becomes (0, 100) and the diagonals
    tie. The thin sheet cuts it along the diagonal that is shorter as drawn (1–3),
    not the tie's (through the lowest vertex id, 0–2)."""
    from foldcore.io import read_file
    from foldcore.sheet import build_sheet

    path = tmp_path / "p.svg"
    path.write_text(svg('<polygon points="0,0 100,0 100,100 0.3,100" fill="none" '
                        'stroke="#000"/>'))
    loaded = read_file(path)
    assert np.round(loaded.pattern.vertices / MM_PER_PX, 9).tolist()[3] == [0, -100]

    def diagonal(sheet):
        (ends,) = sheet.vertex_ids[sheet.hinges[sheet.hinge_edge == -1][:, :2]]
        return sorted(ends.tolist())
    assert diagonal(build_sheet(loaded.pattern, merge_straight=True,
                                drawn=loaded.drawing)) == [1, 3]
    assert diagonal(build_sheet(loaded.pattern, merge_straight=True)) == [0, 2]
