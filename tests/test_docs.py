"""The developer pages' examples run as printed: a strategy and an element type are
added by a new file only (docs/adding-a-strategy.md, docs/adding-an-element-type.md)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def python_blocks(page: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "docs" / page).read_text(), re.S)


def run(tmp_path, files: dict, main: str) -> list[str]:
    """Write ``files`` (name → code) to a fresh folder and run ``main`` there in a new
    process (a registry starts empty); its printed lines."""
    for name, code in files.items():
        (tmp_path / name).write_text(code)
    (tmp_path / "main.py").write_text(main)
    proc = subprocess.run([sys.executable, "main.py"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.splitlines()


def test_a_new_strategy_is_one_new_file(tmp_path):
    """The page's module, saved as my_strategies.py, registers ``relaxed``; the usage
    block folds the hinge with it and with ``paper`` to the same angle, and the
    over-relaxed map takes fewer iterations (ω = 1.8 on a map contracting slowly)."""
    module, usage, convergence = python_blocks("adding-a-strategy.md")
    lines = run(tmp_path, {"my_strategies.py": module}, usage)
    rows = {line.split()[0]: line.split()[1:] for line in lines}
    assert rows["paper"][0] == rows["relaxed"][0] == "converged"
    assert float(rows["paper"][2]) == float(rows["relaxed"][2]) == 60.0
    assert int(rows["relaxed"][1]) < int(rows["paper"][1])
    lines = run(tmp_path, {}, convergence)
    rows = {line.split()[0]: line.split()[1:] for line in lines}
    assert rows["EnergyBelow"][0] == rows["ConvergenceTest"][0] == "converged"
    assert int(rows["EnergyBelow"][1]) <= int(rows["ConvergenceTest"][1])


def test_a_new_element_type_is_one_new_file(tmp_path):
    """The page's module is examples/plugin_bar/bar.py as it is, and its usage block
    folds a hinge propped by a bar of that type short of its target."""
    module, usage = python_blocks("adding-an-element-type.md")[:2]
    assert module == (ROOT / "examples" / "plugin_bar" / "bar.py").read_text()
    lines = run(tmp_path, {"bar.py": module}, usage)
    reason, _, angle = lines[-1].split()
    # a 30 mm strut between edges 2 × 19 mm from the hinge: cos(φ/2) ≈ 30 / 38 (+ the
    # hinge's own chord, − H sin(φ/2)), φ ≈ 80°, far short of the 90° target
    assert reason == "converged" and 75.0 < float(angle) < 85.0


LINKED = ("src", "tests", "docs", "examples", "README.md", "CHANGELOG.md")


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lowercase, stripped, only letters, digits,
    spaces and hyphens kept, spaces to hyphens."""
    kept = "".join(c for c in heading.strip().lower() if c.isalnum() or c in " -")
    return kept.replace(" ", "-")


def text_files():
    for name in LINKED:
        path = ROOT / name
        files = [path] if path.is_file() else sorted(path.rglob("*"))
        for file in files:
            if file.is_file() and "__pycache__" not in file.parts:
                try:
                    yield file, file.read_text()
                except UnicodeDecodeError:  # binary (images, caches)
                    continue


def test_every_architecture_anchor_is_a_heading_of_the_page():
    """Code and docs link design notes by the page's name and a heading's anchor:
    each anchor is a heading of docs/architecture.md (outside code blocks), so no
    link dangles after a heading is renamed."""
    page = re.sub(r"```.*?```", "", (ROOT / "docs" / "architecture.md").read_text(),
                  flags=re.S)
    headings = {slug(line.lstrip("#")) for line in page.splitlines()
                if re.match(r"#{1,6} ", line)}
    missing = sorted({f"{file.relative_to(ROOT)}: #{anchor}"
                      for file, text in text_files()
                      for anchor in re.findall(r"architecture\.md#([a-z0-9-]*)", text)
                      if anchor not in headings})
    assert not missing, "\n".join(missing)


def test_every_relative_link_of_the_docs_points_at_a_file():
    """Relative markdown links of docs/ and README.md name files that exist."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    broken = []
    for page in pages:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
            if re.match(r"[a-z]+:|#", target):  # a URL, or an anchor of the page itself
                continue
            if not (page.parent / target.split("#")[0]).exists():
                broken.append(f"{page.relative_to(ROOT)}: {target}")
    assert not broken, "\n".join(broken)
