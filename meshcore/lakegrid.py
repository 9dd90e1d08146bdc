r"""A lake outline in, a model-ready multiblock grid out: :func:`mesh_outline`.

The pipeline (every step a module of its own):

1. **layout** — :func:`meshcore.layout.auto_layout`: blocks that follow the channels, with cell
   counts that agree across every interface, multiples of ``2**levels``;
2. **start grid** — on the coarsest level (cells ÷ ``2**levels``): the algebraic grid of each
   block, smoothed as one grid by the multiblock Winslow solver, repaired where it folds;
3. **orthogonal grid** — :func:`meshcore.orthogonal.orthogonalize` on every level, coarse to
   fine (:mod:`meshcore.orthogonal.levels`): shore nodes slide along the shore, interface
   nodes move along and across the cut lines, no move may fold a cell;
4. **quality** — :func:`meshcore.quality.lake_metrics` against the water polygon.

The result is a :class:`~meshcore.multiblock.MultiBlockGrid` (``mode="orthogonal"``) whose
``info`` says what was done and whose ``notes`` are the layout's (what was changed in the water:
islands left out, a shore smoothed, …; ``meshcore mesh`` prints them as notes).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Generator
from typing import TYPE_CHECKING, Any

import numpy as np

from .cellsize import DEFAULT_CELLS
from .errors import FoldedGridError, InvalidInputError
from .grid import SolveInfo

if TYPE_CHECKING:
    from .elliptic import SolverProgress

__all__ = [
    "CoarseReadings",
    "coarse_reading",
    "iterate_layout",
    "level_labels",
    "mesh_layout",
    "mesh_outline",
    "retry_words",
]


def _shore_rings(poly, step: float) -> list[np.ndarray]:
    import shapely

    dense = shapely.segmentize(poly, step)
    return [np.asarray(dense.exterior.coords)[:-1], *(np.asarray(r.coords)[:-1] for r in dense.interiors)]


def _layout_shore(layout):
    """The shore the nodes slide along: the water as the layout's pieces have it (every vertex a
    block has on the shore; outline counter-clockwise, islands clockwise, as ``layout.polygon``).

    Taken from the pieces, not from ``layout.polygon``: the case file of a layout writes this shore
    (:func:`~meshcore.layout.outline.outline_parts`), so a layout read back from it slides its nodes
    along the same vertices and gives the same grid to the last bit (from the polygon, the two
    shores followed the same lines through different vertices, and the rounding moved a repaired
    sliver by 0.12 cells on Shasta at 15 000 cells)."""
    import shapely
    from shapely.geometry.polygon import orient

    from .layout.outline import shore_of

    outer, holes = shore_of(list(layout.pieces))
    return orient(shapely.Polygon(outer, holes), 1.0)


def _repair_folds(grids: list) -> tuple[list, int]:
    """Per-block fold-free repair (borders fixed) of any block with invalid cells."""
    from .foldfree import invalid_cells, repair

    out, fixed = [], 0
    for g in grids:
        x = np.asarray(g.x, dtype=float)
        y = np.asarray(g.y, dtype=float)
        if invalid_cells(x, y).any():
            r = repair(g, strict=False)
            out.append(r.grid)
            fixed += 1
        else:
            out.append(g)
    return out, fixed


def _per_level(value, lev: int) -> float:
    """A number, or one per level (coarse first; the last one repeats)."""
    if isinstance(value, (int, float)):
        return float(value)
    return float(value[min(lev, len(value) - 1)])


#: The most iterations of the start grid's solve (a start for the orthogonal levels, not a
#: result): its multigrid converges in 2–7 cycles on 60 real lakes' coarsest levels, but where
#: it gives up, the SOR it falls back to ran to the default 50 000 sweeps, not converging, on
#: one (held-out lake g180645, 47 blocks, 1007 coarse cells: 11.7 CPU-s of its 17.5); capped,
#: the same final quality (folded cells 1 → 1, nodes within 3° 90.3 → 91.1 %) in 7.2 CPU-s.
START_ITERATIONS = 2000


def _start(topo, how: str, g0: list | None = None, stop_event: Any = None):
    """A start grid on the coarsest level: the algebraic (TFI) grids relaxed as one grid
    (``g0``: those grids, :func:`~meshcore.multiblock.initial_grids`, if made already; ``stop_event``
    set ends the Winslow solve with its grids as they are)."""
    from .multiblock import initial_grids, solve_multiblock
    from .orthogonal import orthogonalize

    g0 = initial_grids(topo) if g0 is None else g0
    note = ""
    if how == "winslow":
        mb = solve_multiblock(topo, max_iterations=START_ITERATIONS, initial=g0, stop_event=stop_event)
        grids = list(mb.grids)
        stopped = stop_event is not None and stop_event.is_set()
        if mb.info.converged or stopped or not escaped(grids, g0):
            return grids, f"multiblock Winslow ({mb.info.message})"
        note = f"; the multiblock Winslow start left the lake's extent ({mb.info.message})"
    res = orthogonalize(topo, g0, [], max_sweeps=300, smooth=1.0, omega=1.5, guard=False, tol=1e-4, size_ratio=None)
    return list(res.grids), f"algebraic grids relaxed as one grid ({res.sweeps} sweeps){note}"


#: How far (a share of the extent of the start's algebraic grids) a node of the Winslow start may
#: lie outside that extent before the start counts as diverged (:func:`escaped`).
ESCAPE_MARGIN = 0.01


def escaped(grids: list, g0: list) -> bool:
    """Whether a node of ``grids`` lies outside the bounding box of the algebraic grids ``g0`` (whose
    borders are the blocks' borders) by more than :data:`ESCAPE_MARGIN` of its size.  Winslow's
    equations obey a maximum principle: their solution stays in the convex hull of its borders, so
    a start that leaves it diverged (a multiblock SOR that blew up on a tangled coarse level)."""
    lo = np.min([np.min(np.stack([np.asarray(g.x), np.asarray(g.y)]), axis=(1, 2)) for g in g0], axis=0)
    hi = np.max([np.max(np.stack([np.asarray(g.x), np.asarray(g.y)]), axis=(1, 2)) for g in g0], axis=0)
    pad = ESCAPE_MARGIN * float(np.max(hi - lo))
    for g in grids:
        x, y = np.asarray(g.x), np.asarray(g.y)
        if not (np.isfinite(x).all() and np.isfinite(y).all()):
            return True
        if x.min() < lo[0] - pad or x.max() > hi[0] + pad or y.min() < lo[1] - pad or y.max() > hi[1] + pad:
            return True
    return False


def mesh_layout(
    layout, *, callback: Callable[[str, Any], Any] | None = None, readings: CoarseReadings | None = None, **options: Any
):
    """The orthogonal multiblock grid of a :class:`~meshcore.layout.Layout`.

    The options are those of :func:`iterate_layout`; ``callback("level", (level, result))``
    is called after each level (coarse first).  ``readings``: the :class:`CoarseReadings` that
    chose ``layout`` (:func:`~meshcore.layout.auto_layout`'s ``reading``): its solve held after
    the coarse level goes on, the same grid without solving that level again.
    """
    from ._generators import drain

    if readings is not None:
        mb = readings.resumed(layout, callback, options)
        if mb is not None:  # held for the layout as read, before its arms were set (:func:`_same_layout`)
            return dataclasses.replace(mb, arms=layout.arms)
    return drain(iterate_layout(layout, level_callback=callback, every=None, **options))


class CoarseReadings:
    """:func:`coarse_reading` that holds each layout's solve after its coarse level: the grid of the
    layout then chosen (``mesh_layout(layout, readings=...)``) goes on from there instead of solving
    that level again (the same steps, the same grid; the layout's first reading and its grid were
    two solves of its coarse level).  ``levels``: as :func:`mesh_layout` will be given them.

    >>> from meshcore import testing
    >>> from meshcore.layout import auto_layout
    >>> readings = CoarseReadings(levels=2)
    >>> lay = auto_layout(testing.y_junction(), target_cells=800, multiple=4, reading=readings)
    >>> held, fresh = mesh_layout(lay, levels=2, readings=readings), mesh_layout(lay, levels=2)
    >>> all(np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y) for a, b in zip(held.grids, fresh.grids))
    True
    """

    def __init__(self, levels: int | None = None, *, every: int | None = None, stop_event: Any = None) -> None:
        self.levels = levels
        #: :func:`iterate_layout`'s ``every`` and ``stop_event`` of the held solves (they change no grid: a
        #: caller that goes on with a held solve itself, :meth:`held`, gets its snapshots and its stops)
        self.every, self.stop_event = every, stop_event
        # (layout, paused solve, coarse level, callback box, the progress it paused on)
        self._held: list[tuple[Any, Any, Any, list, Any]] = []

    def __call__(self, layout) -> tuple[float, float, float]:
        """:func:`coarse_reading` of ``layout``, its solve held."""
        first: list = []
        box: list = [None]  # the callback of :meth:`mesh`, for the levels after the first

        def level(kind: str, value: Any) -> Any:
            if kind == "level" and not first:
                first.append(value)
                return "pause"
            return box[0](kind, value) if box[0] is not None else None

        gen = iterate_layout(
            layout, levels=self.levels, level_callback=level, every=self.every, stop_event=self.stop_event
        )
        try:
            paused = next(gen)
            while not first:  # the coarse level's snapshots (``every``): on to its end, where it pauses
                paused = next(gen)
        except StopIteration as fin:  # one level: nothing to hold
            grids = fin.value.grids
        else:
            grids = first[0][1].grids
            self._held.append((layout, gen, first[0], box, paused))
        return _reading(grids)

    def held(self, layout, callback: Callable[[str, Any], Any] | None = None):
        """The solve of ``layout`` held after its coarse level, taken from here, or None: ``(solve, level,
        progress)``, the paused :func:`iterate_layout` generator (``callback`` told of its later levels),
        the ``(level, result)`` of its coarse level (not yet told to ``callback``) and the
        :class:`~meshcore.elliptic.SolverProgress` it paused on.  What is sent to it next goes on
        (``None``) or stops (``"stop"``)."""
        for k, (lay, gen, done, box, paused) in enumerate(self._held):
            if _same_layout(lay, layout):
                del self._held[k]
                box[0] = callback
                return gen, done, paused
        return None

    def resumed(self, layout, callback: Callable[[str, Any], Any] | None, options: dict[str, Any]):
        """The grid of ``layout`` from its held solve (``callback`` told of its coarse level first), or
        None: none held for it, or ``options`` (of :func:`mesh_layout`) other than ``levels`` as
        given to this object (the readings were solved with the defaults)."""
        if options != {"levels": self.levels}:
            return None
        taken = self.held(layout, callback)
        if taken is None:
            return None
        gen, done, _ = taken
        said = callback("level", done) if callback is not None else None
        try:
            gen.send("stop" if said == "stop" else None)
            while True:  # (snapshots only with ``every``)
                gen.send(None)
        except StopIteration as fin:
            return fin.value


def _same_layout(a, b) -> bool:
    """``b`` is ``a``, or ``a`` with other ``details`` or ``arms`` (:func:`dataclasses.replace` keeps the
    other fields)."""
    import dataclasses

    skip = ("details", "arms")
    return a is b or all(getattr(a, f.name) is getattr(b, f.name) for f in dataclasses.fields(a) if f.name not in skip)


#: The share of the coarse grid's cross-interface area ratios at or below the ratio a reading
#: gives (the 99th percentile; 100: the largest).  One coarse cell pair sets the largest: held-out
#: g180670's layout at 0.93 × read 7 607 against 3.06 and g180713's 4.79 against 2.88, their final
#: grids 1.96 and 1.98, and :mod:`.layout.choice` turned down grids 5–6 points more within 3°.
READING_PERCENTILE = 99.0


def _reading(grids) -> tuple[float, float, float]:
    from .quality import lake_metrics

    m = lake_metrics(list(grids))
    summary = m.summary()
    d, least = summary["mean_deviation_deg"], summary["min_edge_cells"]
    v = np.asarray(m.values("interface_ratio"), dtype=float)
    r = float(np.percentile(v, READING_PERCENTILE)) if len(v) else 1.0
    return (float("inf") if d is None else float(d)), r, (1.0 if least is None else float(least))


def coarse_reading(layout) -> tuple[float, float, float]:
    """The mean deviation from 90° (degrees) of the block-interior nodes of ``layout``'s grid on
    the coarsest level of :func:`mesh_layout` (cells ``layout.multiple`` × the size), the
    :data:`READING_PERCENTILE` th percentile of its cross-interface cell-area ratios and its
    shortest edge in its mean cell sizes (a collapsed cell: :data:`~meshcore.layout.choice.COLLAPSED`): what
    :func:`~meshcore.layout.auto_layout` (``reading=``) compares layouts drawn at neighbouring
    scales by (:mod:`meshcore.layout.choice`)."""
    grids = mesh_layout(layout, callback=lambda kind, _: "stop" if kind == "level" else None).grids
    return _reading(grids)


def iterate_layout(
    layout,
    *,
    start: str = "winslow",
    levels: int | None = None,
    sweeps: tuple[int, ...] = (200, 150, 400),
    stall: float | None = 0.0025,
    stall_limits: tuple[float, ...] | None = None,
    smooth: float | tuple[float, ...] = 0.0,
    omega: float = 1.8,
    pin_angle: float | None = None,
    shore_smooth: float = 0.15,
    size_ratio: tuple[float, float] | None = (1.15, 2.0),
    hold_ends: bool = False,
    end_ratio: float | None = None,
    slide_ends: bool = False,
    equalize: bool = True,
    spacing: bool = False,
    every: int | None = 25,
    level_callback: Callable[[str, Any], Any] | None = None,
    stop_event: Any = None,
) -> Generator[SolverProgress, Any, Any]:
    """:func:`mesh_layout` as a generator of :class:`~meshcore.elliptic.SolverProgress`.

    ``sweeps`` are the most sweeps per level, the finest level last (with fewer levels the
    coarsest ones are dropped, with more the first repeats).  ``stall``: the finest level stops
    as soon as its share of nodes with ``|cos| ≤ 0.02`` rises by less than that over 20 sweeps
    and its share within 3° by less than that too (``stall_limits``, default
    :data:`~meshcore.orthogonal.driver.STALL_LIMITS`; see
    :func:`~meshcore.orthogonal.iterate_orthogonalize`; None: always ``sweeps[-1]``).
    ``hold_ends``: keep the lines leaving cut ends at reflex shore corners near their angles
    (:func:`~meshcore.orthogonal.iterate_orthogonalize`; off by default, see there).
    ``end_ratio``: cut ends on the shore where both blocks have a corner slide until their two
    shore edges differ by this ratio (:func:`~meshcore.orthogonal.iterate_orthogonalize`; off).
    ``slide_ends``: block corners and cut ends of cells still non-convex slide along the shore
    (:func:`~meshcore.orthogonal.untangle.untangle` given the shore rings; off by default: on fresh
    generated lakes it removed the one folded cell of ``rough net`` 158200 and 263202 but gave
    ``dendritic(911700)`` 2 and left 263202's shore 0.98 cells off, 0.35 before).  A grid whose
    levels end with folded or non-convex cells is made again with it, and that grid returned when
    it has fewer (:data:`FOLD_RETRY`).
    ``equalize``: after the finest level, the nodes round every interface pair above 2 moved to
    make its two cells alike within bounds on what that may cost elsewhere
    (:func:`~meshcore.orthogonal.equalize.equalize_interfaces`; on by default, ``equalize=False`` skips it).
    ``spacing``: then the edge lengths along grid lines smoothed in block interiors, guarded
    (:func:`~meshcore.orthogonal.spacing.smooth_spacing`; off by default, see there).
    ``level_callback(kind, value)`` is called with ``("level", (level, result))`` as each level
    ends (returning ``"stop"`` ends the solve there, as ``"stop"`` sent does; ``"pause"`` yields
    the level's grids, then goes on or stops as told by what is sent) and
    ``("equalize", patches)`` after the equalize step (the patches it kept); when the grid is made
    again (:data:`FOLD_RETRY`), ``("retry", bad cells)`` before, each of that run's calls with its
    kind prefixed ``"again "`` (its return value not heard), and ``("retried", (bad cells, bad cells
    of the grid made again, whether that grid is the one returned))`` after.
    Every ``every`` sweeps it yields the current grids of every block (``grids``; on the
    coarse levels, the coarse grids); ``"stop"`` sent to it, or ``stop_event`` set, ends the
    solve with the grids as they are (``info.converged`` False, message "stopped"); ``stop_event``
    set during the equalize step ends that between two patches (the patches kept so far stay).  Returns
    the :class:`~meshcore.multiblock.MultiBlockGrid` (``mode="orthogonal"``).
    """
    from .elliptic import SolverProgress
    from .multiblock import MultiBlockGrid, initial_grids
    from .orthogonal import iterate_orthogonalize
    from .orthogonal.driver import SHORE_GAP, STALL_LIMITS
    from .orthogonal.levels import coarsen_topology, fit_bends, fit_ends, refine, refine_shore
    from .orthogonal.untangle import untangle

    t0 = time.perf_counter()
    tol = 1e-5
    topo = layout.topology()
    if levels is None:
        levels = max(0, int(np.log2(layout.multiple))) if layout.multiple > 1 else 0
    factor = 2**levels
    tops = [coarsen_topology(topo, 2**k) if k else topo for k in range(levels, -1, -1)]
    g0 = initial_grids(tops[0])  # the start's first guess, and the layout's lines for untangle
    # stop_event is looked at between the steps too: on a lake of 1.7 million cells the start solve (it
    # did not look), the repairs and the untangling before the first sweep took half a minute after a Stop
    asked = stop_event.is_set if stop_event is not None else (lambda: False)
    grids, how = _start(tops[0], start, g0, stop_event)
    repaired = untangled = 0
    if not asked():
        grids, repaired = _repair_folds(grids)
    rings = _shore_rings(_layout_shore(layout), layout.cell_size / 4)
    if not asked():
        grids, untangled = untangle(tops[0], grids, layout=g0, rings=rings if slide_ends else None)
    total = 0
    fitted = 0
    history: list[tuple[int, float]] = []
    stopped = False
    equalized = 0
    spaced = 0
    for lev, tp in enumerate(tops):
        if asked():  # before the next level's refinement, fits and untangling (the grids of the last one)
            stopped = True
            break
        if lev:
            grids = refine_shore(refine(grids), tp, rings)
        # shore edges that cut across a bend (coarse edges, midpoints of the refinement, a cut end
        # short of a tip): their node put on the bend, for the shore sweep to keep there
        gap = SHORE_GAP * layout.cell_size * 2 ** (len(tops) - 1 - lev)
        grids, n = fit_ends(grids, tp, rings, gap, fine=layout.cell_size)
        fitted += n
        grids, n = fit_bends(grids, tp, rings, gap)
        fitted += n
        if lev:
            grids, n = untangle(tp, grids, rings=rings if slide_ends else None)
            untangled += n
        gen = iterate_orthogonalize(
            tp,
            grids,
            rings,
            every=every,
            tol=tol,
            max_sweeps=sweeps[max(0, len(sweeps) - len(tops) + lev)],
            smooth=_per_level(smooth, lev),
            omega=omega,
            pin_angle=pin_angle,
            shore_smooth=shore_smooth,
            size_ratio=size_ratio,
            hold_ends=hold_ends,
            end_ratio=end_ratio,
            stall=stall if lev == len(tops) - 1 else None,
            stall_limits=STALL_LIMITS if stall_limits is None else tuple(stall_limits),
        )
        try:
            it, d, snap = next(gen)
            while True:
                history.append((total + it, d))
                cmd = yield SolverProgress(
                    total + it, d, tol, None, time.perf_counter() - t0, "orthogonal", tuple(history), snap
                )
                stopped = stopped or cmd == "stop" or (stop_event is not None and stop_event.is_set())
                it, d, snap = gen.send("stop" if stopped else None)
        except StopIteration as fin:
            res = fin.value
        grids = list(res.grids)
        total += res.sweeps
        said = level_callback("level", (lev, res)) if level_callback is not None else None
        if said == "pause":  # held here (:class:`CoarseReadings`); what is sent next goes on or stops
            held = time.perf_counter()
            change = history[-1][1] if history else 0.0
            said = yield SolverProgress(total, change, tol, None, held - t0, "orthogonal", tuple(history), tuple(grids))
            t0 += time.perf_counter() - held  # (the elapsed time: the solve's own)
        if said == "stop":
            stopped = True  # (no more levels wanted: the grids of this one)
        if stopped:
            break
    if not stopped:
        # a fold the coarse level could not resolve (a block corner beside a sharp bend of the
        # shore is non-convex at 2**levels cells but not on the finest level): repaired there
        grids, fine_repaired = _repair_folds(grids)
        if equalize:
            from .orthogonal.equalize import equalize_interfaces

            should_stop = asked if stop_event is not None else None
            grids, equalized = equalize_interfaces(tp, grids, rings, should_stop=should_stop)
            stopped = asked()  # the app's Stop during the step: ends it between patches
            if level_callback is not None:
                level_callback("equalize", equalized)
        if spacing:
            from .orthogonal.spacing import smooth_spacing

            grids, spaced = smooth_spacing(grids)
            if level_callback is not None:
                level_callback("spacing", spaced)
    elapsed = time.perf_counter() - t0
    if stopped:
        msg = "stopped"
    else:
        msg = f"orthogonal grid on {len(tops)} level(s) (cells ÷ {factor} … 1), {total} sweeps; start: {how}"
        if repaired:
            msg += f"; {repaired} coarse block(s) repaired by the fold-free method"
        if fitted:
            msg += f"; {fitted} shore node(s) put on bends of the shore their edges cut across"
        if untangled:
            msg += f"; {untangled} node(s) moved across cut lines to make their cells convex"
        if fine_repaired:
            msg += f"; {fine_repaired} block(s) repaired by the fold-free method on the finest level"
        if equalized:
            msg += f"; {equalized} patch(es) round interface pairs above 2 made alike"
        if spaced:
            msg += f"; {spaced} node move(s) smoothing the spacing along grid lines"
    info = SolveInfo(method="orthogonal", converged=not stopped, iterations=total, elapsed=elapsed, message=msg)
    grids = _block_infos(grids, info)
    names = tuple(b.name for b in topo.blocks)
    # stopped on a coarse level: the grid of that level, with its topology
    mb = MultiBlockGrid(
        tuple(grids), names, tp.interfaces, "orthogonal", info, tp, notes=tuple(layout.notes), arms=layout.arms
    )
    if stopped or slide_ends or not FOLD_RETRY or not (n := _n_folded(grids)):
        return mb
    # cells left folded or non-convex: the levels again with block corners and cut ends sliding (FOLD_RETRY)
    from ._generators import drain

    heard: Callable[[str, Any], None] | None = None
    if level_callback is not None:  # told as "retry", its levels and step as "again level", "again equalize"
        level_callback("retry", n)
        told = level_callback
        heard = lambda kind, value: told(f"again {kind}", value)  # noqa: E731

    # (``every`` as given: its snapshots are dropped, but the app's Stop is heard within as many sweeps; with
    # None a Stop waited for the end of the level, 0.7 s of the 0.9 s full level of dendritic(370703) at 15 000)
    again = drain(
        iterate_layout(
            layout, start=start, levels=levels, sweeps=sweeps, stall=stall, stall_limits=stall_limits,
            smooth=smooth, omega=omega, pin_angle=pin_angle, shore_smooth=shore_smooth, size_ratio=size_ratio,
            hold_ends=hold_ends, end_ratio=end_ratio, slide_ends=True, equalize=equalize, spacing=spacing,
            every=every, level_callback=heard, stop_event=stop_event,
        )
    )  # fmt: skip
    m = _n_folded(again.grids)
    kept = not (asked() or again.info.message == "stopped" or m >= n)
    if level_callback is not None:
        level_callback("retried", (n, m, kept))
    if not kept:
        return mb
    said = f"; made again with block corners and cut ends sliding along the shore: {n} → {m} bad cell(s)"
    info = dataclasses.replace(again.info, message=again.info.message + said)
    return dataclasses.replace(again, info=info, grids=tuple(_block_infos(list(again.grids), info)))


#: A grid whose levels end with folded or non-convex cells is made once more with ``slide_ends`` (block
#: corners and cut ends of cells still bad slide along the shore on every level; without progress
#: reports, ``stop_event`` still heard, within ``every`` sweeps as in the first run), and that grid is
#: taken when it has fewer such cells (session 37: generated dendritic reservoirs ``dendritic(370703)``
#: and ``dendritic(380701)`` at 15 000 cells, 1 and 3 cells at block corners on notches of the shore, 0
#: and 0; ``slide_ends`` for every grid was measured mixed, see :func:`iterate_layout`).
FOLD_RETRY = True


def level_labels(n_levels: int) -> list[str]:
    """The labels of ``n_levels`` levels, coarsest first: ``["cells ÷4", "÷2", "full"]``."""
    return [
        ("cells " if k == 0 else "") + f"÷{2 ** (n_levels - 1 - k)}" if k < n_levels - 1 else "full"
        for k in range(n_levels)
    ]


def retry_words(kind: str, value: Any, labels: list[str], *, stopped: bool = False) -> str | None:
    """What to say of a report of :func:`iterate_layout` (``level_callback(kind, value)``) about the grid
    made again (:data:`FOLD_RETRY`: kinds ``"retry"``, ``"again level"``, ``"again equalize"``,
    ``"retried"``); None for the other reports.  ``labels``: :func:`level_labels`; ``stopped``: the solve
    was stopped meanwhile.  The one wording of ``meshcore mesh`` (which adds the seconds) and the app.

    >>> retry_words("retry", 1, ["cells ÷4", "÷2", "full"])
    'grid: 1 folded or non-convex cell left — making it again with block corners and cut ends sliding along the shore…'
    >>> retry_words("retried", (1, 0, True), [])
    'grid made again: 0 bad cells against 1 — that grid kept'
    """
    if kind == "retry":
        return (
            f"grid: {_counted(value, 'folded or non-convex cell')} left — making it again with block corners and "
            "cut ends sliding along the shore…"
        )
    if kind == "again level":
        lev, res = value
        cells = sum(g.cells[0] * g.cells[1] for g in res.grids)
        label = (labels[lev] if lev < len(labels) else f"level {lev + 1}").removeprefix("cells ")
        done = f"stopped after {res.sweeps} sweeps" if stopped else f"done, {res.sweeps} sweeps"
        return f"grid made again: level {lev + 1}/{len(labels)} ({label}, {cells:,} cells) {done}"
    if kind == "again equalize":
        return f"grid made again: interfaces, {_counted(value, 'patch', 'es')} of cells more than 2× apart made alike"
    if kind == "retried":
        n, m, kept = value
        if stopped:
            return f"grid made again: stopped — the first grid kept ({_counted(n, 'bad cell')})"
        return (
            f"grid made again: {_counted(m, 'bad cell')} against {n} — "
            f"{'that grid kept' if kept else 'the first grid kept'}"
        )
    return None


def _counted(n: int, what: str, plural: str = "s") -> str:
    return f"{n} {what}{plural * (n != 1)}"


def _n_folded(grids) -> int:
    """Folded or non-convex cells of ``grids``."""
    from .quality.lake import block_metrics

    return sum(int(block_metrics(g).folded.sum()) for g in grids)


def _block_infos(grids, info: SolveInfo) -> list:
    """Each block's grid with the orthogonal solve's info (its blocks kept the start solve's, whose
    fold-free repair of a sliver block could report 'no fold-free grid found' for a block the levels
    then made fold-free: ``meshcore generate`` of a lake case exited 3 on a grid with no folded cell);
    a block with folded or non-convex cells left is not converged, and says how many."""
    import dataclasses

    from .quality.lake import block_metrics

    out = []
    for g in grids:
        n = int(block_metrics(g).folded.sum())
        msg = info.message if not n else f"{info.message}; {n} folded or non-convex cell(s) left in this block"
        done = dataclasses.replace(info, converged=info.converged and not n, message=msg)
        out.append(dataclasses.replace(g, info=done))
    return out


def mesh_outline(
    outline: Any,
    *,
    holes: Any = (),
    parts: Any = None,
    cell_size: float | None = None,
    target_cells: int = DEFAULT_CELLS,
    levels: int = 2,
    regular: bool = False,
    single: bool = False,
    strict: bool = False,
    layout_options: Any = None,
    **options: Any,
):
    """A model-ready multiblock grid of a lake outline (projected coordinates, e.g. metres).

    Parameters
    ----------
    outline : (n, 2) array_like, shapely Polygon, MultiPolygon or list of Polygons
        The shore; a Polygon may carry its islands as holes.  Several parts of water (a
        MultiPolygon, a list of Polygons) are meshed at one cell size into one grid whose blocks
        are named ``part<k>_…`` (:mod:`meshcore.lakeparts`).
    holes : sequence of (k, 2) array_like
        Islands (with several parts: each goes to the part that holds it).
    parts : sequence of int, optional
        With several parts: the part numbers to mesh (from 1, largest area first); default all.
    cell_size : float, optional
        Wanted cell size; default ``sqrt(water area / target_cells)``.
    levels : int
        Coarse levels of the grid sequencing (cell counts are multiples of ``2**levels``).
    regular : bool
        Only nodes where four blocks meet (for Delft3D domain decomposition).
    single : bool
        A regular layout whose cell counts also close every ring of blocks round an island in one
        ``(I, J)`` index space (Delft3D single domain, EFDC; :mod:`meshcore.multiblock.closure`).
    strict : bool
        Raise :class:`~meshcore.errors.FoldedGridError` if the grid has folded cells
        (otherwise ``info.converged`` is False and the message names them).
    layout_options : meshcore.layout.LayoutOptions, optional
        Layout choices that are off by default (thin arms, mouths, curve, wedges; each measured
        mixed, :class:`~meshcore.layout.LayoutOptions`).
    **options
        Passed to :func:`mesh_layout` (the orthogonal stage: ``spacing``, ``callback``, …).

    Returns
    -------
    MultiBlockGrid
        Its ``notes`` say what the layout changed in the water (islands narrower than two cells
        left out, arms too narrow for a block, a shore smoothed below the cell size, …), each in
        a sentence naming the place; ``info.message`` says how many there are.
    """
    from .lakeparts import is_several, mesh_parts
    from .layout import LayoutOptions, auto_layout

    if is_several(outline):
        opts = dict(
            levels=levels, regular=regular, single=single, strict=strict, layout_options=layout_options, **options
        )
        return mesh_parts(
            outline, mesh_outline, holes=holes, parts=parts, cell_size=cell_size, target_cells=target_cells, **opts
        )
    if parts is not None:
        raise InvalidInputError("parts= is for water in several parts (a MultiPolygon or a list of Polygons)")
    readings = CoarseReadings(levels=levels)  # the chosen layout's coarse level solved once
    lay = auto_layout(
        outline,
        holes=holes,
        cell_size=cell_size,
        target_cells=target_cells,
        multiple=2**levels,
        regular=regular,
        single=single,
        options=layout_options or LayoutOptions(),
        reading=readings,
    )
    mb = mesh_layout(lay, levels=levels, readings=readings, **options)
    if mb.notes:
        n = len(mb.notes)
        mb = _with_info(mb, message=f"{mb.info.message}; {n} layout note{'s' * (n != 1)} (grid.notes)")
    folded = _n_folded(mb.grids)
    if folded:
        msg = f"{mb.info.message}; {folded} folded or non-convex cell(s) remain"
        if strict:
            raise FoldedGridError(msg)
        mb = _with_info(mb, converged=False, message=msg)
    return mb


def _with_info(mb, **changes):
    import dataclasses

    return dataclasses.replace(mb, info=dataclasses.replace(mb.info, **changes))
