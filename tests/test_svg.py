"""SVG crease patterns in Origami Simulator's colours."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from foldcore.errors import PatternError, PatternWarning
from foldcore.io import Reading, read
from foldcore.io.svg import MM_PER_PX

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


@pytest.mark.parametrize("body, needles", [
    ('<line x1="50" y1="0" x2="50" y2="100" stroke="#0f0"/>', ["line", "cut"]),
    ('<path id="c" d="M50 0 Q90 50 50 100" stroke="#f00" fill="none"/>',
     ["path", "'c'", "curved"]),
    ('<line x1="50" y1="0" x2="50" y2="100" stroke="#f00"/>'
     '<line id="b" x1="50" y1="0" x2="50" y2="100" stroke="#00f"/>',
     ["'b'", "overlap", "different"]),
])
def test_what_foldcore_cannot_fold_is_refused_naming_the_element(tmp_path, body, needles):
    with pytest.raises(PatternError) as info:
        read_text(tmp_path, svg(SQUARE + body))
    message = str(info.value)
    assert "p.svg" in message and "\n" not in message
    for needle in needles:
        assert needle in message, message


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
