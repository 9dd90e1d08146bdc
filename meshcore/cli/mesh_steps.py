"""The steps of ``meshcore mesh`` that a lake in one part and water in several parts share
(:mod:`.mesh` and :mod:`.mesh_parts`): progress lines, the cell size, the layout, the grid, the
guard that turns a pipeline's errors into exit codes, and :func:`finish` (world coordinates,
quality, verdicts, the outputs)."""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from pathlib import Path
from typing import Any

from ..cellsize import DEFAULT_CELLS, SMALL_BLOCKS, default_cell_size, finer_for_small_blocks, small_blocks_reason
from ..errors import InvalidInputError, MeshcoreError
from .lakefile import in_world
from .mesh_figure import figure as _figure

#: Fewest cells asked for (``--cells``, or the cell size's ``area / H²``).
MIN_CELLS = 16
#: Largest coordinate (after the local origin) the pipeline meshes: a circle of radius 1e75 meshes,
#: one of 1e80 made the layout's triangulation fail (Qhull: "initial simplex is flat"), exit 1.
MAX_COORDINATE = 1e75


#: Coarse levels of the grid sequencing (cell counts are multiples of ``2**LEVELS``).
LEVELS = 2


class _Say:
    """Progress lines on stderr (nothing with ``-q``)."""

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self.t0 = time.perf_counter()

    def __call__(self, msg: str) -> None:
        if not self.quiet:
            print(msg, file=sys.stderr, flush=True)

    def lap(self) -> float:
        t, self.t0 = self.t0, time.perf_counter()
        return self.t0 - t


# ------------------------------------------------------------------ stages
def _crs_label(crs: str | None) -> str:
    if crs is None:
        return "no CRS: the grid keeps the file's coordinates"
    from ..crs import crs_name

    try:
        name = f" ({crs_name(crs)})"
    except Exception:  # a label only: the CRS itself was checked by meshcore.crs
        name = ""
    return f"grid CRS {crs}{name}"


def _world(mb: Any, poly: Any, frame: Any) -> tuple[Any, Any, Any]:
    """The grid, the water and the frame in world coordinates (origin added, frame origin 0)."""
    from shapely import affinity

    ox, oy = frame.origin
    if ox == 0.0 and oy == 0.0:
        return mb, poly, frame
    grids = tuple(g.replaced(x=g.x + ox, y=g.y + oy) for g in mb.grids)
    world = dataclasses.replace(frame, origin=(0.0, 0.0))
    arms = None if mb.arms is None else tuple(affinity.translate(p, ox, oy) for p in mb.arms)
    return dataclasses.replace(mb, grids=grids, frame=world, arms=arms), affinity.translate(poly, ox, oy), world


def lake_table(args: argparse.Namespace, poly: Any, h: float, regular: bool) -> Any:
    """The ``[lake]`` table of a ``--case`` file (:class:`meshcore.case.LakeSection`): the water the
    layout was made of (shore, islands: the case's own shore carries every vertex its blocks put on
    it) and the settings, so the app reopens the lake as read and lays it out again alike.  The cell
    size is kept when given (``--cell-size`` or ``--cells``), else "automatic"."""
    import numpy as np

    from ..case import LakeSection

    return LakeSection(
        shore=np.asarray(poly.exterior.coords)[:-1],
        islands=tuple(np.asarray(r.coords)[:-1] for r in poly.interiors),
        cell_size=None if args.cell_size is None and not args.cells else float(h),
        regular=bool(regular),
        single=bool(getattr(args, "single_space", False)),
    )


def _cell_size(args: argparse.Namespace, poly: Any, unit: str) -> tuple[float, str]:
    """The cell size and how it was chosen; refused when the grid would pass the node limit."""
    from .._validation import max_nodes

    big = max(abs(v) for v in poly.bounds)
    if not big <= MAX_COORDINATE:
        raise InvalidInputError(
            f"{args.outline}: coordinates reach {big:.3g}{unit}; meshcore mesh works with coordinates up to "
            f"{MAX_COORDINATE:.0e}: give the outline in larger units"
        )
    area = float(poly.area)
    if args.cell_size is not None:
        h, why = float(args.cell_size), "--cell-size"
    else:
        n = args.cells or DEFAULT_CELLS
        h = default_cell_size(area, n)
        why = f"sqrt(water area / {n})"
    est = area / h / h  # not area / h², which underflows to 0 for h ≈ 1e-200
    if est > max_nodes():
        raise InvalidInputError(
            f"{args.outline}: {why} {h:.4g}{unit} gives about {est:,.0f} cells; the limit is "
            f"{max_nodes():,} nodes (set MESHCORE_MAX_NODES to raise it)"
        )
    if est < MIN_CELLS:
        raise InvalidInputError(
            f"{args.outline}: {why} {h:.4g}{unit} gives about {est:.2g} cells for a water area of "
            f"{area:.4g}{unit + '²' if unit else ''}; give a cell size of at most "
            f"{math.sqrt(area / MIN_CELLS):.4g}{unit}"
        )
    return h, f"cell size {h:.4g}{unit} ({why}, about {est:,.0f} cells)"


def check_not_a_line(args: argparse.Namespace, poly: Any, h: float, unit: str, frame: Any = None) -> None:
    """Refuse water narrower where it is widest than the cell size its own area gave
    (:func:`meshcore.lakeparts.on_one_line`: the layout had nothing to put a block in, an internal
    error after a minute and a half).  A cell size given with ``--cell-size`` is the user's and is
    kept (a channel narrower than a cell still gets blocks)."""
    if args.cell_size is not None:
        return
    from ..lakeparts import on_one_line

    why = on_one_line(poly, h, unit)
    if why:
        why = why.replace("give a cell size of", "give a --cell-size of")
        raise InvalidInputError(in_world(f"{args.outline}: {why}", frame))


def _notes(notes: Any, frame: Any = None) -> None:
    """What the pipeline changed in the water (islands joined or too small): shown even with -q
    (places in the grid's CRS: :func:`in_world`)."""
    for n in notes:
        print(f"meshcore mesh: note: {in_world(n, frame)}", file=sys.stderr)


#: ``--layout-option`` names: the fields of :class:`~meshcore.layout.LayoutOptions`, with dashes.
LAYOUT_OPTIONS = (
    "curve",
    "thin-arms",
    "mouths",
    "wedges",
    "tees",
    "bulges",
    "tapers",
    "lookahead",
    "islands-apart",
)


def layout_options(args):
    """The :class:`~meshcore.layout.LayoutOptions` that ``--layout-option`` asked for."""
    from ..layout import LayoutOptions

    return LayoutOptions(**{name.replace("-", "_"): True for name in args.layout_option})


def _layout(args, poly, h: float, regular: bool, say: _Say, frame: Any = None, readings: Any = None):
    """The automatic layout (``readings``: a :class:`~meshcore.lakegrid.CoarseReadings` of ``LEVELS``
    levels, for :func:`_grid` to go on from the chosen layout's coarse level)."""
    from ..lakegrid import coarse_reading
    from ..layout import LayoutOptions, auto_layout

    options = layout_options(args)
    try:
        lay = auto_layout(
            poly,
            cell_size=h,
            multiple=2**LEVELS,
            regular=regular,
            single=getattr(args, "single_space", False),
            options=options,
            reading=coarse_reading if readings is None else readings,
        )
    except InvalidInputError as exc:  # its places go to the grid's CRS in guarded(), once
        msg = str(exc)
        raise InvalidInputError(msg if msg.startswith(str(args.outline)) else f"{args.outline}: {msg}") from None
    n = len(lay.blocks)
    say(
        f"layout: {n} block{'s' * (n != 1)}, {lay.n_cells:,} cells"
        f"{' (regular: no 3- or 5-block corners)' if regular else ''}"
        f"{f' (options: {options})' if options != LayoutOptions() else ''}, {say.lap():.1f} s"
    )
    finer = finer_for_small_blocks(n, lay.n_cells, lay.cell_size)
    if finer is not None:
        say(f"hint: {small_blocks_reason(n, lay.n_cells)}; --cells {finer[0]} gives each block about {SMALL_BLOCKS}")
    _notes(lay.notes, frame)
    return lay


def _grid(lay, say: _Say, readings: Any = None):
    from ..lakegrid import level_labels, mesh_layout, retry_words

    n_levels = LEVELS + 1
    labels = level_labels(n_levels)

    def level(kind: str, value: Any) -> None:
        # the grid made again (cells left folded or non-convex, lakegrid.FOLD_RETRY): the words the app shows, timed
        again = retry_words(kind, value, labels)
        if again is not None:
            say(f"{again.removesuffix('…')}, {say.lap():.1f} s")
            return
        if kind == "equalize":
            say(f"interfaces: {value} patch(es) of cells more than 2× apart across a cut made alike, {say.lap():.1f} s")
            return
        if kind != "level":
            return
        lev, res = value
        f = 2 ** (LEVELS - lev)
        cells = sum(g.cells[0] * g.cells[1] for g in res.grids)
        scale = f"cells ÷ {f}" if f > 1 else "full"
        say(f"grid level {lev + 1}/{n_levels} ({scale}, {cells:,} cells): {res.sweeps} sweeps, {say.lap():.1f} s")

    return mesh_layout(lay, levels=LEVELS, callback=level, readings=readings)


# ------------------------------------------------------------------ the command
def guarded(args: argparse.Namespace, frame: Any, make):
    """``make()``, its errors told in the grid's CRS (:func:`in_world`); None after an error that is a
    bug of the pipeline, not bad input (one line on stderr, exit 1 for the caller)."""
    try:
        return make()
    except MeshcoreError as exc:
        msg = in_world(str(exc), frame)
        if msg == str(exc):
            raise
        raise type(exc)(msg) from None
    except Exception as exc:
        print(
            f"meshcore mesh: internal error while making the grid of {args.outline} "
            f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]}); please report it with the file",
            file=sys.stderr,
        )
        return None


def _beside(p: Path, fmt: str) -> str:
    """The files a format writes beside ``p``, as the end of the "wrote" line."""
    if fmt == "efdc":
        from ..io.efdc import FILES

        return f" and {', '.join(FILES[1:])} beside it"
    if fmt == "delft3d-dd":
        return f" and a .grd and .enc of every block beside it ({p.stem}_*)"
    if fmt in ("delft3d", "delft3d-single") and p.with_suffix(".enc").exists():
        return f" and {p.with_suffix('.enc').name}"
    return ""


def finish(
    args, mb, poly, frame, h: float, outputs, say: _Say, t_start: float, per_part: Any = None, left_out=()
) -> int:
    """World coordinates, quality, outputs, figure, table and exit code (``per_part(mb, poly)``:
    lines printed before the table, ``left_out``: parts drawn dashed, for water in several parts)."""
    from shapely import affinity

    from ..io import write
    from ..quality import check, lake_metrics

    left_out = [affinity.translate(p, *frame.origin) for p in left_out]
    mb, poly, frame = _world(dataclasses.replace(mb, frame=frame), poly, frame)
    m = lake_metrics(mb, polygon=poly, cell_size=h)
    n_folded = int(m.values("folded").sum())
    say(f"quality: {n_folded} folded cells, mean deviation from 90° {m.mean('deviation'):.2f}°, {say.lap():.1f} s")
    for p, fmt in outputs:
        write(p, mb, fmt.name, crs=frame)
        say(f"wrote {p}{_beside(p, fmt.name)}")
    if args.png:
        _figure(Path(args.png), mb, poly, frame, args.colour, m, left_out)
        say(f"wrote {args.png}")
    if not args.quiet:
        for line in per_part(mb, poly) if per_part is not None else ():
            print(line)
        print(m.table())
        for name in dict.fromkeys(args.preset or ()):
            print("\n" + check(m, name).table())
        print(f"\n{len(mb.grids)} blocks, {m.summary()['cells']:,} cells in {time.perf_counter() - t_start:.1f} s")
    for w in m.coverage.warnings():  # islands lost or cut across: shown even with -q
        print(f"meshcore mesh: warning: {w}", file=sys.stderr)
    small = m.small_cell_note()  # a cell far smaller than the rest: also with -q
    if small:
        print(f"meshcore mesh: note: {small}", file=sys.stderr)
    lost = len(m.coverage.islands_lost)
    if n_folded or not mb.converged or lost:
        why = f"{n_folded} folded or non-convex cells" if n_folded else "the solver did not converge"
        why = why if n_folded or not mb.converged else f"{lost} island(s) under the grid"
        print(f"meshcore mesh: warning: {why} (exit code 3)", file=sys.stderr)
        return 3
    return 0
