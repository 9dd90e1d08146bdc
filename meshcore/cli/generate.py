"""``meshcore generate CASE -o OUT [--png FIG]``.

Every output path is checked before the solve (a format that can be written,
its optional dependency installed, an existing writable folder), so a bad
``--png`` never leaves a fresh ``-o`` file behind after an exit 2.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from ..case import generate_case, load_case
from ..elliptic import SolverProgress
from ..errors import InvalidInputError


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("case", help="case file (.toml)")
    p.add_argument("-o", "--output", help="output mesh file (format from the suffix: .vts, .xyz, .npz, ...)")
    p.add_argument("--png", help="also draw the grid to this figure file (.png/.svg/.pdf)")
    p.add_argument("--method", help="solver method (auto, sor, multigrid, ...)")
    p.add_argument("--tolerance", type=float, help="relative tolerance of the stopping rule")
    p.add_argument("--max-iterations", type=int, help="iteration cap")
    p.add_argument("--threads", type=int, help="solver threads: 0 = all cores on large grids (default), 1 = serial")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress or quality table")


class _Progress:
    """Progress on stderr once a solve has taken more than ~1 s."""

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self.t0 = time.perf_counter()
        self.shown = False

    def __call__(self, snap: SolverProgress) -> None:
        if self.quiet or snap.elapsed < 1.0:
            return
        self.shown = True
        print(
            f"\r  {snap.method}: iteration {snap.iteration:6d}  residual {snap.residual:.3e} "
            f"(tolerance {snap.tolerance:.1e})  {snap.elapsed:5.1f} s",
            end="",
            file=sys.stderr,
            flush=True,
        )

    def done(self) -> None:
        if self.shown:
            print(file=sys.stderr)
            self.shown = False


def probe_folder(p: Path, option: str) -> None:
    """Create and remove a temporary file next to ``p``: a folder that the permission bits call
    writable may still refuse (``/proc``, a read-only mount as root, a full disk), and an output
    refused only after the others were written left those behind on an exit 2."""
    import tempfile

    from ..io._atomic import temp_prefix

    folder = p.parent if str(p.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=temp_prefix(p), suffix=".tmp", dir=folder)
    except OSError as exc:
        raise InvalidInputError(f"{option} {p}: cannot write in the folder {folder} ({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(tmp)


def check_output(path: str, option: str, *, blocks: int = 1, figure: bool = False) -> Path:
    """Refuse an output path that cannot be written, before any work is done.

    Checks the suffix (a format meshcore writes; ``figure``: an image), the
    format's optional dependency, the number of blocks it holds, and that the
    folder exists and is writable.  Raises :class:`InvalidInputError` naming
    ``option`` and the path.
    """
    from ..errors import WriteError
    from ..io import find_format

    p = Path(path)
    if p.is_dir():
        raise InvalidInputError(f"{option} {p}: is a folder, not a file")
    try:
        fmt = find_format(p, None, role="write")
    except WriteError as exc:
        if figure:  # the figure suffixes, not every grid format's (was: '.cgns .csv .ddb ...' for --png x.jpg)
            raise InvalidInputError(f"{option} {p}: expected a figure file (.png, .svg or .pdf)") from None
        raise InvalidInputError(f"{option} {exc}") from None
    if figure and fmt.name != "figure":
        raise InvalidInputError(f"{option} {p}: expected a figure file (.png, .svg or .pdf)")
    missing = fmt.missing()
    if missing:
        raise InvalidInputError(f"{option} {p}: {missing}")
    if blocks > 1 and not fmt.multiblock:
        raise InvalidInputError(
            f"{option} {p}: the {fmt.name} format holds one block and this case has {blocks}; "
            f"write .vtm, .cgns, .su2, .msh, .xyz, .npz or .csv"
        )
    folder = p.parent if str(p.parent) else Path(".")
    if not folder.is_dir():
        raise InvalidInputError(f"{option} {p}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InvalidInputError(f"{option} {p}: cannot write in the folder {folder} (permission denied)")
    probe_folder(p, option)
    if p.suffix.lower() == ".vtm":  # its blocks go to a folder of its name, which must be its own
        from ..io.vtk_xml import check_block_folder

        try:
            check_block_folder(p, p.with_suffix(""))
        except WriteError as exc:
            raise InvalidInputError(f"{option} {exc}") from None
    return p


def run(args: argparse.Namespace) -> int:
    from ..crs import frame_from_case
    from ..io import write
    from ..quality import quality

    case = load_case(args.case)
    n_blocks = len(getattr(case, "blocks", ()) or ())
    if args.output:
        check_output(args.output, "-o", blocks=n_blocks)
    if args.png:
        check_output(args.png, "--png", figure=True)
    frame = frame_from_case(case)
    overrides = {}
    if args.method:
        overrides["method"] = args.method
    if args.tolerance is not None:
        overrides["tolerance"] = args.tolerance
    if args.max_iterations is not None:
        overrides["max_iterations"] = args.max_iterations
    if args.threads is not None:
        overrides["threads"] = args.threads
    try:
        cfg = case.solver.replaced(**overrides)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{args.case}: {exc}") from None
    prog = _Progress(args.quiet)
    t0 = time.perf_counter()
    result = generate_case(case, callback=prog, solver=cfg)
    prog.done()
    elapsed = time.perf_counter() - t0
    blocks = list(getattr(result, "blocks", result))
    frame = getattr(result, "frame", None) or frame  # multiblock outline cases project lon/lat
    if args.output:
        write(Path(args.output), result, crs=frame)
    if args.png:
        write(Path(args.png), result, crs=frame)
    converged = all(g.converged for g in blocks)
    reports = [quality(g) for g in blocks]
    folded = sum(r.n_folded for r in reports)
    if not args.quiet:
        block_names = list(getattr(result, "names", [b.name for b in case.blocks]))
        for k, g in enumerate(blocks):
            name = block_names[k] if k < len(block_names) else ""
            print(
                f"block {name!r}: {g.cells[0]}×{g.cells[1]} cells, {g.info.method}, "
                f"{g.info.message}, {g.iterations} iterations, residual {g.residual:.3e}"
            )
            print(reports[k].table())
        if hasattr(result, "report"):  # multiblock: connectivity and interface quality
            print(result.report())
            print(result.quality(reports).table())
        print(f"done in {elapsed:.3f} s" + (f"; wrote {args.output}" if args.output else ""))
    if not converged:
        print("meshcore generate: warning: the solver did not converge (exit code 3)", file=sys.stderr)
        return 3
    if folded:  # a folded grid is never reported as a success (e.g. repair = "off" in the case)
        print(f"meshcore generate: warning: the grid has {folded} folded cell(s) (exit code 3)", file=sys.stderr)
        return 3
    return 0
