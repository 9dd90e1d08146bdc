"""``meshcore mesh`` of a file that holds several separate parts of water (:mod:`meshcore.lakeparts`).

A lake split at a causeway, dam or bridge, a reservoir and a separate pond, several KML
placemarks: every ring outside every other part's shore is a part of its own (largest first,
numbered from 1), its islands the rings inside it.  The parts are listed while reading (name,
area, centroid in the file's coordinates), meshed at one cell size (``sqrt(total water area /
cells)`` by default), each laid out and solved on its own, and joined into one grid whose blocks
are named ``part<k>_<block>``; ``--part N`` meshes some of them.  A part narrower than three
cells is left out with a note.  The quality table is printed per part and for the whole grid.
``--case LAYOUT.toml`` writes one case per part (``LAYOUT_part<k>.toml``): a case holds one lake.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import InvalidInputError
from .lakefile import in_world
from .mesh_outputs import one_block_only

__all__ = ["WaterParts", "read_parts", "run_parts"]


@dataclass(frozen=True)
class WaterParts:
    """The parts of the water read from a file (local coordinates), largest first."""

    names: tuple[str, ...]
    polygons: tuple[Any, ...]


def _user_place(x: float, y: float, frame: Any, size: float = 0.0) -> str:
    """A local point in the file's own coordinates (lon/lat for degrees, else the grid's CRS),
    rounded to a millionth of ``size`` (the part's extent: no -6.1e-14 for a centre on an axis)."""
    import math

    q = 10.0 ** math.floor(math.log10(1e-6 * size)) if size > 0 else 0.0
    wx, wy = (float(v) for v in frame.to_world(x, y)) if frame is not None else (x, y)
    if q > 0:
        wx, wy = round(wx / q) * q + 0.0, round(wy / q) * q + 0.0
    src, crs = getattr(frame, "source_crs", None), getattr(frame, "crs", None)
    if src and crs and src != crs:
        import pyproj

        from ..crs import is_geographic

        lon, lat = pyproj.Transformer.from_crs(crs, src, always_xy=True).transform(wx, wy)
        if is_geographic(src):
            return f"lon {lon:.5f}, lat {lat:.5f}"
        return f"({lon:.6g}, {lat:.6g}) in {src}"
    return f"({wx:.6g}, {wy:.6g})"


def read_parts(args: Any, parts: list, frame: Any, say: Any) -> WaterParts:
    """Each part's water polygon (checked as one lake's), listed on stderr; overlapping parts refused."""
    import shapely

    from ..lakeparts import water_parts
    from ..layout.polygon import water_polygon
    from .mesh_steps import _crs_label, _notes

    names, polys = [], []
    for k, (name, outer, islands) in enumerate(parts, 1):
        try:
            poly, notes = water_polygon(outer, holes=islands)
        except InvalidInputError as exc:
            raise InvalidInputError(in_world(f"{args.outline}: part {k} ({name!r}): {exc}", frame)) from None
        _notes([f"part {k} ({name!r}): {n}" for n in notes], frame)
        names.append(name)
        polys.append(poly)
    try:  # cleaned rings may meet where the file's did not
        water_parts(shapely.MultiPolygon(polys))
    except InvalidInputError as exc:
        raise InvalidInputError(in_world(f"{args.outline}: {exc}", frame)) from None
    n = len(polys)
    where = f" from {frame.source_crs}" if frame.source_crs and frame.source_crs != frame.crs else ""
    say(f"read {args.outline}: {n} separate part{'s' * (n != 1)} of water; {_crs_label(frame.crs)}{where}")
    km = frame.crs is not None
    for k, (name, p) in enumerate(zip(names, polys, strict=True), 1):
        c = p.centroid
        area = f"{p.area / 1e6:.4g} km²" if km else f"{p.area:.6g}"
        isl = f", {len(p.interiors)} island{'s' * (len(p.interiors) != 1)}" if len(p.interiors) else ""
        say(f"  part {k}: {name!r}, area {area}, centroid {_user_place(c.x, c.y, frame, p.length)}{isl}")
    return WaterParts(tuple(names), tuple(polys))


def _layouts(args: Any, water: WaterParts, kept: list, h: float, regular: bool, say: Any, frame: Any) -> list:
    from ..lakegrid import coarse_reading
    from ..layout import auto_layout
    from .mesh_steps import LEVELS, _notes, layout_options

    lays = []
    for k, p in kept:
        try:
            lay = auto_layout(
                p,
                cell_size=h,
                multiple=2**LEVELS,
                regular=regular,
                single=getattr(args, "single_space", False),
                options=layout_options(args),
                reading=coarse_reading,
            )
        except InvalidInputError as exc:  # its places go to the grid's CRS in guarded(), once
            raise InvalidInputError(f"{args.outline}: part {k}: {exc}") from None
        nb = len(lay.blocks)
        say(
            f"part {k} ({water.names[k - 1]!r}): layout: {nb} block{'s' * (nb != 1)}, {lay.n_cells:,} cells, "
            f"{say.lap():.1f} s"
        )
        _notes([f"part {k}: {n}" for n in lay.notes], frame)
        lays.append(lay)
    return lays


def _check_blocks(outputs: list, kept: list, lays: list) -> None:
    """As :func:`meshcore.cli.mesh_outputs.check_blocks`, for the blocks of every part together."""
    import tempfile

    from ..algebraic import tfi
    from ..errors import WriteError
    from ..io import write

    n_blocks = sum(len(lay.blocks) for lay in lays)
    for p, fmt in outputs:
        if n_blocks > 1 and not fmt.multiblock:
            raise InvalidInputError(one_block_only(p, fmt, f"the parts have {n_blocks}", single=False))
        if fmt.name not in ("delft3d-dd", "delft3d-single", "efdc"):
            continue
        single = [k for (k, _), lay in zip(kept, lays, strict=True) if len(lay.blocks) == 1]
        if single and fmt.name == "delft3d-dd":
            k = single[0]
            others = ",".join(str(j) for j, _ in kept if j != k)
            raise InvalidInputError(
                f"-o {p}: part {k} is one block, and a .ddb lists only blocks coupled to another (parts do not "
                f"couple): write it apart (--part {k} -o part{k}.grd) and the rest with --part {others}, or write "
                f".vtm, .cgns or .xyz"
            )
        grids, names = [], []
        for (k, _), lay in zip(kept, lays, strict=True):
            topo = lay.topology()
            grids += [tfi(b.borders) for b in topo.blocks]
            names += [f"part{k}_{b.name}" for b in topo.blocks]
        with tempfile.TemporaryDirectory(prefix="meshcore-mesh-") as d:
            trial = Path(d) / p.name
            try:
                write(trial, grids, fmt.name, block_names=names)
            except WriteError as exc:
                msg = str(exc).replace(f"{trial}: ", "").replace(str(trial), str(p))
                also = " (write .vtm, .cgns or .xyz instead)" if fmt.name == "delft3d-dd" else ""
                raise InvalidInputError(f"-o {p}: {msg}{also}") from None


def _per_part(water: WaterParts, kept: list, h: float):
    def lines(mb: Any, poly: Any) -> list[str]:
        from ..lakeparts import part_grids
        from ..quality import lake_metrics
        from ..quality.samples import ok_percent

        out = [
            "| part | name | blocks | cells | folded | mean deviation | nodes within 3° | shore distance (cells) |",
            "|---|---|---|---|---|---|---|---|",
        ]
        grids = part_grids(mb)
        for (k, _), p in zip(kept, getattr(poly, "geoms", [poly]), strict=True):
            s = lake_metrics(grids[k], polygon=p, cell_size=h).summary()
            out.append(
                f"| {k} | {water.names[k - 1]} | {s['blocks']} | {s['cells']:,} | {s['folded_cells']} | "
                f"{s['mean_deviation_deg'] or 0:.2f}° | {ok_percent((s['pct_nodes_within_3deg'] or 0) / 100)} % | "
                f"{s['hausdorff_cells']:.2f} |"
            )
        return [*out, ""]

    return lines


def run_parts(args: Any, water: WaterParts, frame: Any, say: Any, outputs: list, regular: bool, t_start: float) -> int:
    """The rest of ``meshcore mesh`` for water in several parts (exit codes as there)."""
    import shapely

    from ..lakeparts import join_grids, select_parts
    from .mesh_steps import _cell_size, _grid, _notes, check_not_a_line, finish, guarded

    unit = " m" if frame.crs else ""
    total = shapely.MultiPolygon(list(water.polygons))
    h, how = _cell_size(args, total, unit)
    area = f"{total.area / 1e6:.4g} km²" if frame.crs else f"{total.area:.6g}"
    say(f"water area {area} in {len(water.polygons)} parts, {how}")
    asked = [k for group in args.part for k in group] if args.part else None
    try:
        kept, notes = select_parts(list(water.polygons), asked, h, water.names)
    except InvalidInputError as exc:
        raise InvalidInputError(in_world(f"{args.outline}: {exc}", frame)) from None
    for _, p in kept:
        check_not_a_line(args, p, h, unit, frame)
    _notes(notes, frame)
    if asked:
        say(f"meshing part{'s' * (len(kept) != 1)} {', '.join(str(k) for k, _ in kept)} of {len(water.polygons)}")
    say.lap()

    def make():
        lays = _layouts(args, water, kept, h, regular, say, frame)
        _check_blocks(outputs, kept, lays)
        results = []
        for (k, _), lay in zip(kept, lays, strict=True):
            say(f"part {k}:")
            results.append((k, _grid(lay, say)))
        return lays, join_grids(results, notes)

    made = guarded(args, frame, make)
    if made is None:
        return 1
    lays, mb = made
    if args.case:  # one case per part: a case holds one lake
        from ..case import layout_case, save_case
        from .mesh_steps import lake_table

        for (k, part), lay in zip(kept, lays, strict=True):
            path = Path(args.case).with_name(f"{Path(args.case).stem}_part{k}.toml")
            what = f"made by meshcore mesh from part {k} ({water.names[k - 1]!r}) of {args.outline}"
            case = layout_case(lay, crs=frame, description=what).replaced(lake=lake_table(args, part, h, regular))
            save_case(case, path)
            say(f"wrote {path} (part {k}'s layout: edit it and run 'meshcore generate {path}')")
    poly = shapely.MultiPolygon([p for _, p in kept]) if len(kept) > 1 else kept[0][1]
    out = [p for k, p in enumerate(water.polygons, 1) if k not in dict(kept) and (not asked or k in asked)]
    return finish(args, mb, poly, frame, h, outputs, say, t_start, per_part=_per_part(water, kept, h), left_out=out)
