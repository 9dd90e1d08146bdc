"""Generating a case: every block on its own, or all blocks together (multiblock)."""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable, Generator
from typing import Any

from .._generators import drain
from ..elliptic import EllipticConfig, SolverProgress
from ..errors import CaseFileError, InvalidInputError
from ..generate import generate_block
from ..grid import StructuredGrid
from ..spec import SolverSpec
from .model import Case
from .multiblock import case_frame, case_layout, case_topology_frame

__all__ = ["case_solver", "generate_case", "iterate_multiblock_case"]


def case_solver(case: Case, solver: SolverSpec | EllipticConfig | None = None) -> SolverSpec:
    """The solver of a case run: ``case.solver``, or ``solver`` (an EllipticConfig keeps the case's repair)."""
    if solver is None:
        return case.solver
    if isinstance(solver, EllipticConfig):
        return SolverSpec.from_config(solver, repair=case.solver.repair)
    return solver


def generate_case(
    case: Case,
    *,
    callback: Callable[[SolverProgress], Any] | None = None,
    solver: SolverSpec | EllipticConfig | None = None,
    config: SolverSpec | EllipticConfig | None = None,
) -> Any:
    """Generate every block of ``case``.

    Single-block cases give a list of :class:`StructuredGrid` (one per block,
    each generated on its own); multiblock cases (``[multiblock]``,
    ``[[interfaces]]``, ``[outline]``) a :class:`meshcore.multiblock.MultiBlockGrid`.
    ``callback`` sees every :class:`SolverProgress`; ``solver`` (or ``config``)
    replaces the case's solver settings.
    """
    spec = case_solver(case, solver if solver is not None else config)
    if case.is_multiblock:
        return drain(iterate_multiblock_case(case, spec), callback)
    grids: list[StructuredGrid] = []
    for b in case.blocks:
        try:
            grids.append(generate_block(b, spec, callback=callback))
        except CaseFileError:
            raise
        except InvalidInputError as exc:
            raise type(exc)(f"{case.source}: block {b.name!r}: {exc}") from None
    return grids


def iterate_multiblock_case(
    case: Case,
    solver: SolverSpec | EllipticConfig | None = None,
    *,
    topology: Any = None,
    initial: Any = None,
    stop_event: threading.Event | None = None,
) -> Generator[SolverProgress, Any, Any]:
    """A multiblock case's solve as a generator of :class:`SolverProgress` (``grids`` per block).

    Returns the :class:`~meshcore.multiblock.MultiBlockGrid` with the case's
    frame.  ``topology`` (:func:`case_topology`) and ``initial`` grids may be
    given when the caller has them already.
    """
    from ..multiblock.solver import iterate_multiblock

    s = case.settings
    if s.mode == "orthogonal":  # an [outline] lake case: the orthogonal lake grid
        from ..lakegrid import iterate_layout

        mb = yield from iterate_layout(case_layout(case), stop_event=stop_event)
        return dataclasses.replace(mb, frame=case_frame(case))
    if topology is None:
        topology, frame = case_topology_frame(case)
    else:
        frame = case_frame(case)
    mb = yield from iterate_multiblock(
        topology,
        mode=s.mode,
        start=s.start,
        config=case_solver(case, solver).config(),
        initial=initial,
        stop_event=stop_event,
    )
    return dataclasses.replace(mb, frame=frame)
