"""The command line's commands on a result file: ``foldcore render``, ``export`` and
``view`` (each from its parsed arguments to an exit code; bad input raises
:class:`foldcore.errors.FoldcoreError`, which :mod:`foldcore.cli` turns into one
line and exit code 2)."""
from __future__ import annotations

from .destinations import check_destinations


def render_result(args) -> int:
    """Run ``foldcore render``; raises FoldcoreError on bad input. The thick mesh is
    rebuilt from the file (:func:`foldcore.result_file.read_result`): its stored faces
    carry no panel/hinge or M/V information. A thin sheet's result is drawn from
    its triangles (:func:`foldcore.sheet_render.render_sheet_result`)."""
    from .result_file import SheetResultFile, read_result
    from .measure import fold_angles
    from .render import colour_limits, per_strip, render_png, strip_bend_angles

    check_destinations({"-o": args.output}, inputs=(args.result,), suffixes={"-o": (".png",)})
    res = read_result(args.result, args.hinge_width, args.subdivisions, thin=True)
    if isinstance(res, SheetResultFile):
        from .sheet_render import render_sheet_result
        render_sheet_result(res, args.output, args.size, args.view, args.color_by)
        return 0
    options = {}
    if args.color_by == "strain":   # largest surface tension of each sub-strip
        from .strain import strains_at

        values = strains_at(res.mesh.groups["bending_hinge"], res.positions).max(axis=1)
        options = dict(scalars=values, clim=colour_limits(values, signed=False),
                       cmap="viridis", scalar_name="surface tension strain")
    elif args.color_by != "none":   # signed angles, valley > 0: blue, mountain < 0: red
        angle = args.color_by == "angle"
        values = per_strip(res.mesh, fold_angles(res.pattern, res.mesh, res.positions)) \
            if angle else strip_bend_angles(res.mesh, res.positions)
        options = dict(scalars=values, clim=colour_limits(values, signed=True), cmap="RdBu",
                       scalar_name="fold angle (deg)" if angle else "strip bend (deg)")
    render_png(res.pattern, res.mesh, res.positions, args.output, size=args.size,
               view=args.view, **options)
    return 0


def export_result(args) -> int:
    """Run ``foldcore export``; raises FoldcoreError on bad input. A thin sheet's result
    exports its lines and folded triangles (:func:`foldcore.fabrication.export_sheet`)."""
    from .fabrication import ExportError, export, export_sheet
    from .result_file import SheetResultFile, read_result

    if not (args.svg or args.dxf or args.stl):
        raise ExportError(f"{args.result}: nothing to export: give --svg, --dxf and/or --stl")
    check_destinations({"--svg": args.svg, "--dxf": args.dxf, "--stl": args.stl},
                       inputs=(args.result,))
    res = read_result(args.result, args.hinge_width, args.subdivisions, thin=True)
    (export_sheet if isinstance(res, SheetResultFile) else export)(
        res, svg=args.svg, dxf=args.dxf, stl=args.stl, stroke_mm=args.stroke_width,
        margin_mm=args.margin)
    return 0


def view_result(args) -> int:
    """Run ``foldcore view`` (:mod:`foldcore.view`); raises FoldcoreError on bad input."""
    from .view import view_html

    check_destinations({"-o": args.output}, inputs=(args.result,),
                       suffixes={"-o": (".html", ".htm")})
    view_html(args.result, args.output)
    return 0


COMMANDS = {"render": render_result, "export": export_result, "view": view_result}
