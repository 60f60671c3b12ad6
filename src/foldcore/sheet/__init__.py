"""A thin sheet as bars and hinges: Origami Simulator's model, settled by Newton.

``build_sheet(pattern)`` cuts the pattern into triangles and springs
(:mod:`.build`); ``fold_sheet(sheet, fold_percent)`` finds the sheet's static
equilibrium (:mod:`.solve`), the shape Origami Simulator's dynamics settle to.
"""
from .build import Sheet, Stiffness, build_sheet
from .solve import SheetFold, SheetSolver, fold_sheet

__all__ = ["Sheet", "SheetFold", "SheetSolver", "Stiffness", "build_sheet", "fold_sheet"]
