"""The app's document, pure edit functions, hit-testing and undo commands — no window."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from app import geometry as geo
from app import project as pj
from app.commands import Editor
from app.document import Document
from app.pipeline import block_initial_grid, solve_project
from app.project import Block, Project
from meshcore import BorderSpec, borders_from_loop
from meshcore.io.outline import guess_corners


def square_block(n=4, cells=(8, 8)):
    """A square loop with n points per side, corners at the four vertices."""
    t = np.linspace(0, 1, n + 1)[:-1]
    pts = np.vstack([np.c_[t, 0 * t], np.c_[1 + 0 * t, t], np.c_[1 - t, 1 + 0 * t], np.c_[0 * t, 1 - t]])
    return Block(points=pts, closed=True, corners=(0, n, 2 * n, 3 * n), cells=cells)


def test_nearest_point_and_segment():
    p = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert geo.nearest_point(p, (0.98, 0.03), 0.1) == 1
    assert geo.nearest_point(p, (0.5, 0.5), 0.1) is None
    k, t, foot = geo.nearest_segment(p, (0.25, 0.02), 0.05)
    assert (k, t) == (0, pytest.approx(0.25)) and foot == pytest.approx((0.25, 0.0))
    # the closing segment 3 -> 0 counts only for closed loops
    assert geo.nearest_segment(p, (0.01, 0.5), 0.05)[0] == 3
    assert geo.nearest_segment(p, (-0.01, 0.5), 0.05, closed=False) is None
    assert list(geo.points_in_box(p, 1.1, -0.1, 0.5, 1.1)) == [1, 2]
    assert geo.snap((0.97, 1.02), p, 0.05, exclude=[2]) == (0.97, 1.02)
    assert geo.snap((0.97, 1.02), p, 0.05) == (1.0, 1.0)


def test_grid_lines_are_nan_separated_polylines():
    x, y = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    X, Y = geo.grid_lines(x, y)
    assert X.shape == (4 * 4 + 3 * 5,)
    assert np.isnan(X).sum() == 4 + 3
    # first i-line: i = 0, j = 0..2 then NaN
    assert X[:4].tolist()[:3] == [0, 0, 0] and Y[:3].tolist() == [0, 1, 2] and np.isnan(Y[3])


@pytest.mark.parametrize("reverse", [False, True])
def test_auto_corners_of_rotated_rectangle_loop(reverse):
    b = square_block(5)
    pts = np.array(b.points) * [3.0, 1.0]
    th = 0.4
    rot = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    pts = pts @ rot.T
    if reverse:
        pts = pts[::-1].copy()
    c = guess_corners(pts)
    # the chosen points are the rectangle's four vertices
    verts = np.array([[0, 0], [3, 0], [3, 1], [0, 1]]) @ rot.T
    assert sorted(map(tuple, np.round(pts[list(c)], 9))) == sorted(map(tuple, np.round(verts, 9)))
    bd = borders_from_loop(pts, c)  # meshcore accepts them: cyclic order is right
    assert len(bd.bottom) == len(bd.top) == 6


def test_similarity_from_two_pairs():
    a, b, tx, ty = geo.similarity_from_pairs((0, 0), (10, 20), (100, 0), (10, 220))
    m = complex(a, b)
    assert m == pytest.approx(2j) and (tx, ty) == pytest.approx((10, 20))


def test_edit_functions_keep_corners_consistent():
    b = square_block(2)
    assert b.corners == (0, 2, 4, 6)
    b2 = pj.with_point_inserted(b, 0, (0.25, 0.0))
    assert b2.corners == (0, 3, 5, 7) and len(b2.points) == 9
    b3 = pj.with_points_deleted(b2, [1])
    assert b3 == b
    # deleting a corner clears the corners
    assert pj.with_points_deleted(b, [2]).corners is None
    b4 = pj.with_points_moved(b, [1], (0.0, 0.1))
    assert b4.points[1].tolist() == [0.5, 0.1] and b.points[1].tolist() == [0.5, 0.0]
    assert not b4.points.flags.writeable


def test_boundary_polylines_round_trip_to_loop():
    b = square_block(3)
    bd = borders_from_loop(b.points, b.corners)
    poly = Block(boundary=(bd.bottom, bd.right, bd.top, bd.left), cells=(6, 6))
    loop = pj.boundary_to_loop(poly)
    assert loop.ready and loop.boundary is None
    g1, g2 = block_initial_grid(poly), block_initial_grid(loop)
    assert g1 == g2


def test_undo_redo_restore_exact_states():
    pytest.importorskip("PySide6")
    from PySide6.QtGui import QUndoStack

    doc = Document()
    stack = QUndoStack()
    ed = Editor(doc, stack)
    seen = []
    doc.project_changed.connect(seen.append)
    states = [doc.project]
    for xy in [(0, 0), (2, 0), (2, 1), (0, 1)]:
        ed.add_point(xy)
        states.append(doc.project)
    ed.close_loop()
    states.append(doc.project)
    ed.set_corners((0, 1, 2, 3))
    states.append(doc.project)
    drag = ed.new_drag_id()
    for k in range(5):  # a drag merges into a single undo step
        ed.set_point(2, (2 + 0.1 * k, 1 + 0.05 * k), drag_id=drag)
    states.append(doc.project)
    ed.set_border_spec("bottom", BorderSpec("tanh", first=0.01))
    states.append(doc.project)
    ed.set_solver(method="sor", tolerance=1e-5)
    states.append(doc.project)
    assert stack.count() == len(states) - 1
    assert len(seen) >= stack.count()
    for k in range(len(states) - 1, 0, -1):
        assert doc.project == states[k]
        stack.undo()
        assert doc.project == states[k - 1]
        assert doc.project is states[k - 1]  # the very same object: nothing recomputed
    for k in range(1, len(states)):
        stack.redo()
        assert doc.project is states[k]
    assert doc.block.corners == (0, 1, 2, 3) and doc.block.closed
    assert doc.block.points[2].tolist() == pytest.approx([2.4, 1.2])
    # a no-op edit pushes nothing
    n = stack.count()
    ed.set_solver(method="sor")
    assert stack.count() == n


def test_solve_project_generator_returns_grids_and_warm_start_helps():
    proj = Project(blocks=(square_block(4, cells=(16, 16)),))
    p = np.array(proj.blocks[0].points)
    p[2] += (0.0, 0.3)  # bulge the bottom: the algebraic grid is not the solution
    proj = proj.with_block(0, proj.blocks[0].replaced(points=p))
    gen = solve_project(proj)
    seen = []
    try:
        while True:
            seen.append(next(gen))
    except StopIteration as fin:
        res = fin.value
    g = res.grids[0]
    assert g.cells == (16, 16) and g.converged
    k, start = seen[0]
    assert k == 0 and start.grid == res.initial[0] == start.algebraic
    # warm start after a small boundary move converges in fewer iterations
    p2 = p.copy()
    p2[2] += (0.0, 0.02)
    proj2 = proj.with_block(0, proj.blocks[0].replaced(points=p2))
    cold = _drain(solve_project(proj2)).grids[0]
    warm = _drain(solve_project(proj2, warm={0: (res.initial[0], g)})).grids[0]
    assert warm.converged and cold.converged
    assert warm.iterations < cold.iterations
    assert np.abs(warm.x - cold.x).max() < 1e-4


def _drain(gen):
    try:
        while True:
            next(gen)
    except StopIteration as fin:
        return fin.value


@pytest.mark.parametrize("reverse", [False, True])
def test_border_polylines_match_meshcore(reverse):
    b = square_block(3)
    pts = np.array(b.points)
    c = list(b.corners)
    if reverse:
        pts = pts[::-1].copy()
        n = len(pts)
        c = [(n - 1 - k) for k in c]  # the same geometric corners in the reversed loop
    mine = geo.border_polylines(pts, c)
    ref = borders_from_loop(pts, c)
    for name in ("bottom", "right", "top", "left"):
        np.testing.assert_allclose(mine[name], ref[name])


def test_document_model_is_free_of_qt():
    """The document, project, geometry and solve pipeline import no Qt at all."""
    import subprocess
    import sys
    from pathlib import Path

    code = (
        "import sys, app.document, app.project, app.geometry, app.pipeline, app.io_adapter;"
        "bad = sorted(m for m in sys.modules if m.startswith(('PySide6', 'pyqtgraph', 'superqt')));"
        "assert not bad, bad"
    )
    r = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        cwd=Path(__file__).resolve().parents[2],
        timeout=60,
    )
    assert r.returncode == 0, r.stderr


def test_auto_corners_cap_the_tips_of_a_curved_channel():
    """A long curved band (an arc of an annulus): the corners sit at its two ends."""
    th_in = np.linspace(0.0, np.pi, 40)
    outer = np.c_[10 * np.cos(th_in), 10 * np.sin(th_in)]
    inner = np.c_[9 * np.cos(th_in[::-1]), 9 * np.sin(th_in[::-1])]
    loop = np.vstack([outer, inner])[::-1].copy()  # counter-clockwise
    c = guess_corners(loop)
    ends = loop[list(c)]
    # two corners at each end of the band (y ≈ 0, x ≈ ±9..10)
    assert np.all(np.abs(ends[:, 1]) < 1.0)
    assert sorted(np.sign(ends[:, 0])) == [-1, -1, 1, 1]
    b = borders_from_loop(loop, c)
    assert len(b.left) < 6 and len(b.right) < 6  # the short ends are left/right


@pytest.mark.parametrize("angle", [0.0, 0.3, 1.2, 2.0, -2.5])
def test_auto_corners_keep_bottom_at_the_bottom(angle):
    """Whatever the principal axes, SW→SE is the corner pair whose direction is closest to +x."""
    b = square_block(4)
    pts = np.array(b.points) * [2.0, 1.0]
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    pts = pts @ rot.T
    sw, se, ne, nw = guess_corners(pts)
    d = [pts[c1] - pts[c0] for c0, c1 in ((sw, se), (se, ne), (ne, nw), (nw, sw))]
    cos = [v[0] / np.hypot(*v) for v in d]
    assert cos[0] == max(cos)


def test_add_and_delete_blocks_are_undoable():
    from PySide6.QtGui import QUndoStack

    doc = Document(Project(blocks=(square_block(2),)))
    stack = QUndoStack()
    ed = Editor(doc, stack)
    first = doc.project
    ed.add_block()
    assert len(doc.project.blocks) == 2 and doc.active == 1
    ed.delete_block(0)
    assert len(doc.project.blocks) == 1 and not doc.block.closed
    ed.delete_block()
    assert len(doc.project.blocks) == 1 and len(doc.block.points) == 0
    for _ in range(3):
        stack.undo()
    assert doc.project is first


def test_cut_ends_snap_onto_the_outline_as_vertices():
    from meshcore.errors import TopologyError
    from meshcore.multiblock.cutsplit import snap_cuts_to_outline

    ring = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 1.0]])
    new, cuts = snap_cuts_to_outline(ring, [np.array([[1.0, -0.05], [1.1, 1.04]])], snap=0.1)
    assert len(new) == 6
    assert cuts[0][0].tolist() == [1.0, 0.0] and cuts[0][-1].tolist() == [1.1, 1.0]
    assert any(np.array_equal(v, [1.1, 1.0]) for v in new)
    with pytest.raises(TopologyError, match="cut 1"):
        snap_cuts_to_outline(ring, [np.array([[1.0, -0.5], [1.0, 1.0]])], snap=0.1)


DATA = Path(__file__).resolve().parents[1] / "data"
LAKES = sorted((Path(__file__).resolve().parents[2] / "app" / "resources").glob("*.csv"))


@pytest.mark.parametrize("path", [*LAKES, DATA / "lake_zurich_sparse.kml"], ids=lambda p: p.name)
def test_a_point_file_gives_the_same_grid_in_the_app_and_on_the_command_line(tmp_path, path):
    """The app's imported block (corners, cells, grid) = ``meshcore import`` + ``meshcore generate``.

    The grids are compared at an eighth of the default cells (about 10 000 cells: a minute to solve
    twice on a busy machine); the same counts on both sides, as the user would type them.
    """
    import dataclasses

    from app.io_adapter import read_points, to_local
    from app.project import block_from_points
    from meshcore.case import generate_case, load_case
    from meshcore.cli import main

    pd = read_points(path)
    pts, _frame = to_local(pd)
    block = block_from_points(pts, path.stem)
    case_path = tmp_path / "lake.toml"
    assert main(["import", str(path), "-o", str(case_path)]) == 0
    case = load_case(case_path)
    (cb,) = case.blocks
    assert cb.corners == block.corners and cb.cells == block.cells
    small = (max(4, cb.cells[0] // 8), max(4, cb.cells[1] // 8))
    mine = _drain(solve_project(Project(blocks=(block.replaced(cells=small),)))).grids[0]
    (theirs,) = generate_case(dataclasses.replace(case, blocks=(dataclasses.replace(cb, cells=small),)))
    assert mine.converged and theirs.converged
    np.testing.assert_array_equal(mine.x, theirs.x)
    np.testing.assert_array_equal(mine.y, theirs.y)


def _shapes():
    """Generated one-block lakes: a disc, an ellipse, a straight channel, a jagged oval (metres)."""
    import shapely

    from meshcore import testing

    oval = shapely.affinity.scale(shapely.Point(0, 0).buffer(1.0, quad_segs=32), 9_000.0, 2_500.0)
    return {
        "disc": shapely.Point(0, 0).buffer(3_000.0, quad_segs=24),
        "oval": oval,
        "channel": shapely.affinity.scale(testing.straight_channel(10.0, 1.0), 2_000.0, 2_000.0, origin=(0, 0)),
        "jagged oval": testing.jagged(oval, 150.0, seed=3),
    }


@pytest.mark.parametrize("name", ["disc", "oval", "channel", "jagged oval"])
def test_import_defaults_to_the_cell_size_of_meshcore_mesh_and_agrees_with_meshcore_import(tmp_path, name):
    """One block from an imported outline: square cells of ``sqrt(area / 10 000)`` (the cell-size rule
    of ``meshcore mesh``), not 40 along the long side (issue 13: 8×40 for a 30-km lake); the counts
    are those of ``meshcore import`` for the same file."""
    import math

    from app.io_adapter import read_points
    from app.project import block_from_points
    from meshcore.case import load_case
    from meshcore.cellratio import cell_ratio
    from meshcore.cli import main
    from meshcore.cli.mesh import DEFAULT_CELLS

    poly = _shapes()[name]
    ring = np.asarray(poly.exterior.coords)[:-1]
    f = tmp_path / "lake.csv"
    f.write_text("x,y\n" + "".join(f"{x!r},{y!r}\n" for x, y in ring.tolist()))
    pts = read_points(f).points
    block = block_from_points(pts, "lake")
    assert main(["import", str(f), "-o", str(tmp_path / "lake.toml")]) == 0
    (cb,) = load_case(tmp_path / "lake.toml").blocks
    assert (cb.corners, cb.cells) == (block.corners, block.cells)
    # cells of the rule's size (area / h² = DEFAULT_CELLS of them), ni : nj at which the Winslow
    # grid's median cell is square (meshcore.cellratio)
    r = cell_ratio(pts, block.corners)
    ni, nj = block.cells
    assert abs(ni - math.sqrt(DEFAULT_CELLS * r)) <= 0.5 + 1e-9 and abs(nj - math.sqrt(DEFAULT_CELLS / r)) <= 0.5 + 1e-9
    assert 0.5 * DEFAULT_CELLS <= ni * nj <= 2 * DEFAULT_CELLS


def test_a_multiblock_project_yields_live_grids_in_one_thread():
    """The multiblock solve runs in the worker's own thread and shows every block's grid as it goes."""
    import threading

    from app.io_adapter import load_project
    from app.pipeline import ALL_BLOCKS

    project = load_project(
        Path(__file__).resolve().parents[2] / "resources" / "examples" / "confluence-multiblock.toml"
    )
    gen = solve_project(project, report_interval=1e-9)
    threads = threading.active_count()
    items = []
    try:
        while True:
            items.append(next(gen))
            assert threading.active_count() == threads  # no second thread inside the worker
    except StopIteration as fin:
        res = fin.value
    live = [e for k, e in items if k == ALL_BLOCKS]
    assert live and all(len(e.grids) == len(project.blocks) and e.grid is None for e in live)
    assert res.multiblock is not None and res.multiblock.converged
    assert all(np.array_equal(res.grids[k].x, g.x) for k, g in enumerate(res.multiblock.grids))


def test_the_app_pipeline_honours_strict_repair_and_keeps_warnings():
    """The drifts of the old app pipeline, fixed: repair="strict" raises, warnings reach the result."""
    from meshcore import FoldedGridError

    strip = Block(  # one row of cells whose top dips: no fold-free grid exists (as in test_foldfree)
        boundary=(
            np.array([[0, 0], [1, 0], [2, 0]], float),
            np.array([[2, 0], [2, 1]], float),
            np.array([[0, 1], [0.3, 0.1], [2, 1]], float),
            np.array([[0, 0], [0, 1]], float),
        ),
        cells=None,
    )
    project = Project(blocks=(strip,))
    auto = _drain(solve_project(project)).grids[0]
    assert not auto.converged and "no fold-free grid" in auto.info.message
    with pytest.raises(FoldedGridError, match="no fold-free grid"):
        _drain(solve_project(project.replaced(solver=project.solver.replaced(repair="strict"))))
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])  # a repeated point
    res = _drain(solve_project(Project(blocks=(Block(name="sq", points=sq, closed=True, corners=(0, 1, 3, 4)),))))
    assert any("duplicate" in w and w.startswith("sq:") for w in res.warnings)


def test_solver_settings_survive_a_save_from_the_app(tmp_path):
    """repair = "strict" and threads are kept when the app loads and saves a case."""
    from app.io_adapter import load_project, save_project
    from meshcore.case import load_case

    src = Path(__file__).resolve().parents[2] / "resources" / "examples" / "bottle-coarse.toml"
    case = tmp_path / "in.toml"
    case.write_text(src.read_text() + '\n[solver]\nrepair = "strict"\nthreads = 2\n')
    project = load_project(case)
    assert project.solver.repair == "strict" and project.solver.threads == 2
    save_project(project, tmp_path / "out.toml")
    again = load_case(tmp_path / "out.toml").solver
    assert again.repair == "strict" and again.threads == 2


def test_grid_segments_are_every_cell_edge_once():
    rng = np.random.default_rng(3)
    x, y = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    x, y = x + 0.1 * rng.random(x.shape), y + 0.1 * rng.random(y.shape)
    X, Y = geo.grid_segments(x, y)
    assert X.shape == Y.shape == (2 * (4 * 2 + 3 * 3),)
    got = {frozenset({(X[k], Y[k]), (X[k + 1], Y[k + 1])}) for k in range(0, len(X), 2)}
    want = set()
    for i in range(4):
        for j in range(3):
            if j + 1 < 3:
                want.add(frozenset({(x[i, j], y[i, j]), (x[i, j + 1], y[i, j + 1])}))
            if i + 1 < 4:
                want.add(frozenset({(x[i, j], y[i, j]), (x[i + 1, j], y[i + 1, j])}))
    assert got == want


def test_edge_pairs_of_several_grids_are_each_grids_segments_in_turn():
    rng = np.random.default_rng(5)
    shapes = [(int(a), int(b)) for a, b in rng.integers(2, 9, size=(6, 2))]
    grids = [(rng.random(s), rng.random(s)) for s in shapes]
    pairs = geo.edge_pairs(shapes)
    x = np.concatenate([gx.ravel() for gx, _gy in grids])
    y = np.concatenate([gy.ravel() for _gx, gy in grids])
    want = [geo.grid_segments(gx, gy) for gx, gy in grids]
    np.testing.assert_array_equal(x[pairs], np.concatenate([w[0] for w in want]))
    np.testing.assert_array_equal(y[pairs], np.concatenate([w[1] for w in want]))
    assert geo.edge_pairs([]).size == 0
