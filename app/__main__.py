"""``python -m app [FILE] [--example NAME] [--solve] [--screenshot OUT.png]`` (also ``gcmesh``)."""

from __future__ import annotations

import argparse
import logging
import os
import sys
import threading
import time
from pathlib import Path

#: seconds ``--solve`` waits for the layout and the grid (a busy machine may need minutes)
SOLVE_TIMEOUT_S = 1800.0


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="gcmesh", description="gcmesh: structured boundary-fitted grids")
    p.add_argument("file", nargs="?", help="a project (.toml case file) or a boundary point file")
    p.add_argument("--example", metavar="NAME", help="open a bundled example (see the Examples menu)")
    p.add_argument(
        "--solve",
        action="store_true",
        help="generate the grid after opening (a lake outline is laid out first; lon/lat degrees are "
        "projected without asking)",
    )
    p.add_argument(
        "--quality",
        metavar="METRIC",
        default=None,
        help="colour cells by a quality metric after solving (e.g. skewness, deviation); the start of "
        "its name in the Quality panel",
    )
    p.add_argument(
        "--screenshot", metavar="OUT.png", help="render (off screen if there is no display), save a screenshot and exit"
    )
    p.add_argument("--size", default=None, help="window size WxH (default: last session, or 1400x880)")
    return p


def _logging() -> None:
    """Warnings and errors to stderr; everything from INFO up, with tracebacks, to gcmesh.log."""
    from PySide6 import QtCore

    # the terminal's handler has its own level: the "app" logger below passes INFO records (a file that
    # cannot be read, with its traceback) to every handler of the root, whose level does not stop them
    terminal = logging.StreamHandler()
    terminal.setLevel(logging.WARNING)
    terminal.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    logging.getLogger().addHandler(terminal)
    logging.getLogger().setLevel(logging.WARNING)
    loc = QtCore.QStandardPaths.StandardLocation.AppDataLocation
    folder = Path(QtCore.QStandardPaths.writableLocation(loc))
    try:
        folder.mkdir(parents=True, exist_ok=True)
        handler = logging.FileHandler(folder / "gcmesh.log", encoding="utf-8")
    except OSError:
        return
    handler.setLevel(logging.INFO)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    logging.getLogger().addHandler(handler)
    logging.getLogger("app").setLevel(logging.INFO)


def quality_label(text: str) -> str:
    """The colouring metric (a label of :data:`app.document.METRICS`) that ``text`` names.

    Case-insensitive; the start of a label ("deviation", "skew") or of one of its words
    ("ratio" is ambiguous).  Raises ValueError naming the known labels.
    """
    from .document import METRICS

    t = " ".join(text.lower().split())
    for rule in (lambda lab: lab == t, lambda lab: lab.startswith(t), lambda lab: f" {t}" in f" {lab}"):
        hits = [lab for lab in METRICS if rule(lab.lower())]
        if len(hits) == 1:
            return hits[0]
        if len(hits) > 1:
            raise ValueError(f"--quality {text!r} names {len(hits)} metrics: {', '.join(hits)}")
    raise ValueError(f"--quality {text!r}: no such metric; known: {', '.join(METRICS)}")


def main(argv: list[str] | None = None) -> int:
    from meshcore._heap import keep_freed_memory

    keep_freed_memory()
    parser = _parser()
    args = parser.parse_args(argv)
    if args.quality:
        try:
            args.quality = quality_label(args.quality)
        except ValueError as exc:
            parser.error(str(exc))
    if args.screenshot and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    t0 = time.perf_counter()
    # Qt's Python modules first, in this thread alone: shiboken's start-up walks sys.modules, and a
    # module imported meanwhile by the warm-up thread (numba importing numpy.ma) aborted the process
    # ("Fatal Python error: libshiboken/signature: could not initialize part 2", seen under load)
    import pyqtgraph as pg
    from PySide6 import QtCore, QtGui, QtWidgets  # noqa: F401

    # then the numba kernels (warm cache: well under a second) and shapely while the window is made
    from .pipeline import warmup

    warm = threading.Thread(target=warmup, name="gcmesh-warmup", daemon=True)
    warm.start()

    pg.setConfigOptions(antialias=False, background="w", foreground="k")
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(sys.argv[:1])
    app.setApplicationName("gcmesh")
    app.setOrganizationName("gcmesh")
    _logging()

    from .main_window import MainWindow

    win = MainWindow(restore_layout=not args.screenshot)  # screenshots: the default layout

    def excepthook(kind, value, tb):  # a bug in a slot must not leave the user guessing
        logging.getLogger("app").critical("internal error", exc_info=(kind, value, tb))
        win.message(f"internal error: {kind.__name__}: {value} (the traceback is in the log)", error=True)

    sys.excepthook = excepthook
    if args.size or args.screenshot:
        w, h = (int(v) for v in (args.size or "1400x880").lower().split("x"))
        win.resize(w, h)
        win.fit_on_show = False
    if args.screenshot:
        win.quiet = True
    win.show()
    app.processEvents()
    startup = time.perf_counter() - t0
    win.message(f"Ready in {startup:.2f} s. " + win._status.text())
    opened = open_at_start(win, file=args.file, example=args.example, solve=args.solve, screenshot=args.screenshot)
    if not opened and (args.solve or args.screenshot):
        return 2
    # opened by hand (a double-clicked file): the window stays, the error in its message panel
    app.processEvents()
    win.canvas.fit()
    if args.solve:
        if not solve_as_opened(app, win):
            print(f"gcmesh: --solve: not finished after {SOLVE_TIMEOUT_S:.0f} s; {win._status.text()}", file=sys.stderr)
        win.measurer.wait()  # a large grid's quality, measured in a worker (the screenshot shows it)
        app.processEvents()
        if args.quality:
            win.quality_panel.metric.setCurrentText(args.quality)
    if args.screenshot:
        for _ in range(5):
            app.processEvents()
            time.sleep(0.02)
        ok = win.grab().save(args.screenshot)
        win.stack.setClean()
        win.close()
        warm.join(timeout=60)  # a process that ends inside a compiled kernel aborts
        return 0 if ok else 1
    code = app.exec()
    warm.join(timeout=60)
    return code


def open_at_start(win, *, file=None, example=None, solve: bool = False, screenshot=None) -> bool:
    """Open what the command line names (an example, a file), and after a crash offer the autosaved
    project back — also when a file is opened by hand: a file double-clicked after a crash was
    opened without the offer, and its first edit autosaved over the lost session's work.  Restored,
    the file is not opened (the status line names it).  False: the file or example did not open."""
    if example:
        return win.io.open_example(example, confirm=False)
    if not screenshot and not (file and solve) and win.io.offer_recovery(Path(file).name if file else None):
        if file:  # also in the Messages: the status line is the restored lake's grid's a second later
            text = f"Restored the autosaved project of the last session; {Path(file).name} was not opened"
            win.doc.report("info", f"{text} (File ▸ Open opens it)")
            win.message(f"{text} (File ▸ Open project opens it)")
        return True
    if file:  # --solve asks for a grid: lon/lat degrees are projected as the question's default would (no dialog)
        return win.io.open_path(Path(file), project_lonlat=True if solve else None)
    return True


def solve_as_opened(app, win, timeout_s: float | None = None) -> bool:
    """``--solve``: the grid of what was opened, until it is done; False if not done in ``timeout_s``.

    A lake whose import offered Auto layout (a lake on the map, or water with islands or arms) is
    laid out first, as the offer's button does and as ``meshcore mesh`` does; one block over it
    would be far from a model grid (~20° off orthogonal on a compact lake), or cover its islands.  The
    layout and the grid may take minutes on a busy machine: the default wait is
    :data:`SOLVE_TIMEOUT_S` for both together.
    """
    t_end = time.perf_counter() + (SOLVE_TIMEOUT_S if timeout_s is None else timeout_s)
    if win.lake_ctl.prompt is not None:
        done: list = []
        win.lake_ctl.layout_done.connect(done.append)
        if win.lake_ctl.auto_layout():  # the grid starts when the layout is set
            while not done and time.perf_counter() < t_end:
                app.processEvents()
                time.sleep(0.01)
            if not done or done[0] is None:
                return False
    else:
        win.generate()
    return win.solver.wait(timeout_s=max(0.0, t_end - time.perf_counter()))


if __name__ == "__main__":
    sys.exit(main())
