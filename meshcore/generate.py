"""From boundary points to a smooth grid: the block pipeline.

``borders → (re-sample by curve + distribution) → algebraic grid → elliptic solve``.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ._validation import validate_choice, validate_count
from .algebraic import algebraic_grid
from .boundary import Borders, borders_from_loop, borders_from_polylines
from .elliptic import EllipticConfig, SolverProgress, iterate, solve
from .errors import InvalidInputError, MeshcoreError, MeshcoreWarning
from .grid import BORDER_NAMES, StructuredGrid

__all__ = ["generate_block", "initial_grid", "prepare_borders"]


def _cells(cells: Any) -> tuple[int, int] | None:
    if cells is None:
        return None
    try:
        ni, nj = cells
    except (TypeError, ValueError):
        raise InvalidInputError(f"cells must be a pair (ni, nj), got {cells!r}") from None
    return validate_count(ni, name="cells ξ (ni)"), validate_count(nj, name="cells η (nj)")


def prepare_borders(
    bottom: Any = None,
    right: Any = None,
    top: Any = None,
    left: Any = None,
    *,
    loop: Any = None,
    corners: Any = None,
    cells: Any = None,
    borders: Mapping[str, Any] | None = None,
    curve: str = "linear",
    periodic: bool = False,
    snap_angle: float | None = None,
    where: str = "",
) -> Borders:
    """Validate the boundary and re-sample it (or use the given nodes when ``cells`` is None)."""
    if loop is not None:
        if any(v is not None for v in (bottom, right, top, left)):
            raise InvalidInputError("give either four borders or loop + corners, not both")
        if corners is None:
            raise InvalidInputError('a closed loop needs four corner indices (corners=) or corners="auto"')
        if isinstance(corners, str) and corners == "auto":
            from .corners import choose_corners

            corners = choose_corners(loop)
        b = borders_from_loop(loop, corners, where=where)
        if periodic:
            raise InvalidInputError("periodic=True needs four borders (left = right is the seam)")
    else:
        missing = [n for n, v in zip(BORDER_NAMES, (bottom, right, top, left), strict=True) if v is None]
        if missing:
            raise InvalidInputError(f"missing border(s): {', '.join(missing)}")
        b = borders_from_polylines(bottom, right, top, left, periodic=periodic, where=where)
    c = _cells(cells)
    if c is None:
        if borders and any(
            (v or {}).get("distribution", "uniform") != "uniform" if isinstance(v, Mapping) else False
            for v in borders.values()
        ):
            raise InvalidInputError("border distributions need cells= (the borders are re-sampled)")
        b.check_counts()
        return b
    return b.resampled(c, specs=borders, curve=curve, snap_angle=snap_angle)


def initial_grid(
    borders: Borders,
    *,
    initial: str = "weighted",
    weights: tuple[float, float] = (0.5, 0.5),
    names: Mapping[str, str] | None = None,
) -> StructuredGrid:
    """The algebraic start grid (``weighted`` = paper eq. 34, or ``tfi``)."""
    try:
        w = tuple(weights)
    except TypeError:
        raise InvalidInputError(f"weights must be a pair (p13_x, p13_y), got {weights!r}") from None
    if len(w) != 2:
        raise InvalidInputError(f"weights must be a pair (p13_x, p13_y), got {weights!r}")
    g = algebraic_grid(borders, initial, weights=w)  # type: ignore[arg-type]
    return g.replaced(names=dict(names or {}))


def generate_block(
    bottom: Any = None,
    right: Any = None,
    top: Any = None,
    left: Any = None,
    *,
    loop: Any = None,
    corners: Any = None,
    cells: Any = None,
    weights: tuple[float, float] = (0.5, 0.5),
    initial: str = "weighted",
    curve: str = "linear",
    borders: Mapping[str, Any] | None = None,
    method: str = "auto",
    tolerance: float | None = None,
    max_iterations: int = 50_000,
    omega: float | None = None,
    threads: int = 0,
    p: np.ndarray | None = None,
    q: np.ndarray | None = None,
    config: EllipticConfig | None = None,
    callback: Callable[[SolverProgress], Any] | None = None,
    smooth: bool = True,
    periodic: bool = False,
    repair: str = "auto",
    snap_angle: float | None = None,
    control: Any = None,
) -> StructuredGrid:
    """Generate one block's grid from its boundary.

    Parameters
    ----------
    bottom, right, top, left : (k, 2) array_like
        Border polylines in the orientation of :mod:`meshcore.grid` (bottom/top
        left→right, left/right bottom→top).  Alternatively ``loop`` + ``corners``.
    loop : (n, 2) array_like, optional
        A closed boundary loop; ``corners = (sw, se, ne, nw)`` point indices,
        or ``corners="auto"`` (:func:`meshcore.corners.choose_corners`).
    cells : (ni, nj), optional
        Re-sample each border by the paper's linear spline (or ``curve``),
        uniformly in arc length unless ``borders`` says otherwise.  With
        ``None`` the given points are the boundary nodes.
    weights : (p13_x, p13_y)
        Weights of the left/right interpolation in the paper's eq. 34.
    initial : {"weighted", "tfi"}
        Algebraic start grid.
    curve : {"linear", "cubic", "catmull-rom"}
        Boundary curve used for re-sampling.
    borders : dict, optional
        Per-border :class:`~meshcore.boundary.BorderSpec` (distribution, first,
        last, name), e.g. ``{"bottom": {"distribution": "tanh", "first": 0.01}}``.
    method, tolerance, max_iterations, omega, threads, config
        Solver settings (see :class:`~meshcore.elliptic.EllipticConfig`);
        ``threads``: 0 (default) = all cores on large grids, 1 = serial, ``n`` = ``n``
        threads; every choice gives the same grid bit for bit.
    p, q : array_like, optional
        Source terms P, Q of the node shape (zero by default).
    callback : callable, optional
        Called with each :class:`~meshcore.elliptic.SolverProgress`; return
        ``"stop"`` to stop early.
    smooth : bool
        ``False`` returns the algebraic grid without the elliptic solve.
    periodic : bool
        Periodic ξ direction (O-grid): left and right borders coincide and the
        seam nodes are solved like interior nodes.
    repair : {"auto", "strict", "off"}
        What to do when the elliptic result has folded or non-convex cells
        (a corner Jacobian ≤ 0): ``"auto"`` repairs them with the fold-free
        barrier method (:func:`meshcore.foldfree.repair`; ``info.method``
        becomes e.g. ``"multigrid+foldfree"`` and ``info.message`` says why)
        and, if no fold-free grid exists for these boundary nodes, returns the
        best grid with ``converged=False`` and a message naming the cells and
        the fix; ``"strict"`` raises :class:`~meshcore.errors.FoldedGridError`
        instead; ``"off"`` returns the elliptic result as it is.
        ``method="foldfree"`` minimises the barrier functional over the whole
        block after the elliptic solve (:func:`meshcore.foldfree.smooth`).
    snap_angle : float, optional
        When re-sampling, input vertices where a border turns by more than this
        many degrees get a node exactly (keeps the corners of a cutout);
        ``None`` = pure distribution (the paper).
    control : ControlSpec or mapping, optional
        Grid control (:mod:`meshcore.control`): boundary orthogonality and
        first-cell spacing, Thomas–Middlecoff, attraction, floating nodes
        (which slide on the given border polylines), e.g.
        ``{"borders": {"bottom": {"spacing": 0.01}}}``.

    Returns
    -------
    StructuredGrid
        ``grid.x, grid.y`` of shape ``(ni + 1, nj + 1)``; ``grid.converged``,
        ``grid.iterations`` and ``grid.residual`` describe the solve.

    Examples
    --------
    >>> import meshcore
    >>> g = meshcore.generate_block([[0, 0], [2, 0]], [[2, 0], [2, 1]],
    ...                             [[0, 1], [2, 1]], [[0, 0], [0, 1]], cells=(4, 2))
    >>> g.shape, g.converged
    ((5, 3), True)
    """
    wake = _wake_cells(control)
    if wake:
        # C-grid: the bottom border folds back on itself along the wake cut, so the
        # self-intersection check does not apply; the nodes are used as given
        if cells is not None or loop is not None:
            raise InvalidInputError(
                "a C-grid (control wake > 0) needs four borders given node by node (no cells=, no loop)"
            )
        b = borders_from_polylines(bottom, right, top, left, check_intersections=False)
        b.check_counts()
    else:
        b = prepare_borders(
            bottom,
            right,
            top,
            left,
            loop=loop,
            corners=corners,
            cells=cells,
            borders=borders,
            curve=curve,
            periodic=periodic,
            snap_angle=snap_angle,
        )
    names = {k: v["name"] for k, v in (borders or {}).items() if isinstance(v, Mapping) and v.get("name")}
    g0 = initial_grid(b, initial=initial, weights=weights, names=names)
    if not smooth:
        return g0
    repair = validate_choice(repair, ("auto", "strict", "off"), name="repair")
    foldfree = (config.method if config is not None else str(method).lower()) == "foldfree"
    cfg = config or EllipticConfig(
        method="auto" if foldfree else method,
        tolerance=tolerance,
        max_iterations=max_iterations,
        omega=omega,
        threads=threads,
    )
    sources = None
    if control is not None:
        from .control import make_sources

        curves = {n: b[n] for n in ("bottom", "right", "top", "left")}
        if cells is not None:  # slide on the input polylines, not on the re-sampled nodes
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")  # already reported by prepare_borders
                    if loop is not None:
                        raw = borders_from_loop(loop, corners)
                    else:
                        raw = borders_from_polylines(bottom, right, top, left, periodic=periodic)
                curves = {n: raw[n] for n in curves}
            except MeshcoreError:  # e.g. corners="auto": slide on the re-sampled nodes
                pass
        sources = make_sources(control, periodic=periodic, curves=curves)
    if foldfree and cfg.method == "foldfree":
        cfg = cfg.replaced(method="auto")
    g = solve(g0, cfg, callback=callback, p=p, q=q, sources=sources)
    if foldfree:
        from .foldfree import smooth as _ff_smooth

        if p is not None or q is not None:
            warnings.warn(
                'method="foldfree": the source terms P, Q shape only the elliptic start grid; '
                "the fold-free minimisation has none (the default method keeps them and "
                "repairs only the invalid cells)",
                MeshcoreWarning,
                stacklevel=2,
            )

        return _ff_smooth(g, strict=repair == "strict").grid
    if repair == "off":
        return g
    from .foldfree import repair as _ff_repair

    return _ff_repair(g, strict=repair == "strict").grid


def _wake_cells(control: Any) -> int:
    if control is None:
        return 0
    w = getattr(control, "wake", None)
    if w is None and isinstance(control, Mapping):
        w = control.get("wake", 0)
    return int(w or 0)


# Re-export for convenience
iterate = iterate
