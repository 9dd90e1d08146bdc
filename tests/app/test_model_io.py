"""Qt-free parts of the window's logic: calibration maths, cell look-up, recovery files, quality."""

from __future__ import annotations

import json

import numpy as np
import pytest

from app import geometry as geo
from app import recovery
from app.document import Document
from app.project import Background, Block, Project, SolverSettings
from meshcore import BorderSpec, StructuredGrid
from meshcore.case import load_case


def _apply(tr, uv):
    a, b, tx, ty = tr
    return complex(a, b) * complex(*uv) + complex(tx, ty)


def test_calibration_moves_the_shown_points_onto_the_true_ones():
    tr = (0.5, 0.2, 3.0, -1.0)  # the image as placed now
    u0, u1 = (10.0, 5.0), (200.0, 80.0)  # two pixels of the image ...
    shown = [_apply(tr, u0), _apply(tr, u1)]  # ... drawn here
    true = [(1000.0, 2000.0), (1100.0, 2300.0)]  # ... are really here
    new = geo.compose_similarity(tr, [(z.real, z.imag) for z in shown], true)
    assert _apply(new, u0) == pytest.approx(complex(*true[0]))
    assert _apply(new, u1) == pytest.approx(complex(*true[1]))
    # a similarity: the image's right angles and aspect ratio survive
    a, b, _, _ = new
    w = _apply(new, (1, 0)) - _apply(new, (0, 0))
    h = _apply(new, (0, 1)) - _apply(new, (0, 0))
    assert abs(w) == pytest.approx(abs(h)) == pytest.approx(abs(complex(a, b)))
    assert (w.conjugate() * h).real == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError, match="different"):
        geo.compose_similarity(tr, [(1.0, 1.0), (1.0, 1.0)], true)


def test_fit_image_covers_the_outline_keeping_the_aspect_ratio():
    a, b, tx, ty = geo.fit_image(400, 100, (10.0, 20.0, 110.0, 70.0))
    assert (b, tx, ty) == (0.0, 10.0, 20.0)
    assert 400 * a >= 100.0 - 1e-9 and 100 * a >= 50.0 - 1e-9  # covers both directions
    assert min(400 * a - 100.0, 100 * a - 50.0) == pytest.approx(0.0)  # and no more than it must
    assert geo.fit_image(400, 100, None) == (1.0, 0.0, 0.0, 0.0)


def test_cell_at_finds_the_cell_under_a_point():
    x, y = np.meshgrid(np.linspace(0, 4, 5), np.linspace(0, 2, 3), indexing="ij")
    x = x + 0.1 * y  # sheared a little
    cx, cy = geo.cell_centres(x, y)
    assert cx.shape == (4, 2)
    for i, j in [(0, 0), (3, 1), (2, 0)]:
        assert geo.cell_at(x, y, cx[i, j] + 0.2, cy[i, j] - 0.1) == (i, j)
    assert geo.cell_at(x, y, 100.0, 100.0) is None


def _project():
    t = np.linspace(0, 1, 5)[:-1]
    sq = np.vstack([np.c_[t, 0 * t], np.c_[1 + 0 * t, t], np.c_[1 - t, 1 + 0 * t], np.c_[0 * t, 1 - t]]) * 100
    ready = Block(
        name="lake",
        points=sq,
        closed=True,
        corners=(0, 4, 8, 12),
        cells=(12, 9),
        weights=(0.3, 0.7),
        borders=(("bottom", BorderSpec("tanh", first=2.0, name="shore")),),
    )
    drawing = Block(name="drawing", points=[(0.0, 0.0), (5.0, 1.0), (7.0, 9.0)], cells=(20, 10), curve="cubic")
    return Project(
        blocks=(drawing, ready),
        solver=SolverSettings(method="foldfree", tolerance=1e-7, max_iterations=900, repair="off"),
        cut_lines=(np.array([[50.0, -1.0], [50.0, 101.0]]),),
        background=Background("/tmp/map.png", (2.0, 0.5, -3.0, 4.0)),
        crs="EPSG:32632",
        origin=(500000.0, 4700000.0),
        source_crs="EPSG:4326",
        title="test lake",
    )


def test_recovery_round_trips_a_project_through_the_case_format(tmp_path):
    p = _project()
    path = tmp_path / "recovery.toml"
    recovery.write(p, path, saved_as=tmp_path / "mine.toml")
    assert path.exists() and recovery.sidecar(path).exists()
    assert not path.read_bytes().startswith(b"\x80")  # not a pickle: a case file meshcore reads
    case = load_case(path)
    assert [b.name for b in case.blocks] == ["lake"]  # the block a case can hold
    q, saved = recovery.read(path)
    assert q == p and saved == tmp_path / "mine.toml"
    assert (q.origin, q.source_crs, q.solver) == (p.origin, p.source_crs, p.solver)
    recovery.discard(path)
    assert not recovery.exists(path)


def test_recovery_of_a_project_still_being_drawn(tmp_path):
    p = Project(blocks=(Block(points=[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)], closed=True),))
    path = tmp_path / "r.toml"
    recovery.write(p, path)
    assert not path.exists() and recovery.exists(path)  # nothing for a case file yet
    q, saved = recovery.read(path)
    assert q == p and saved is None


def test_recovery_ignores_a_sidecar_of_another_case(tmp_path):
    p = _project()
    path = tmp_path / "r.toml"
    recovery.write(p, path)
    state = json.loads(recovery.sidecar(path).read_text())
    state["case_sha256"] = "0" * 64  # as after a crash between the two writes
    recovery.sidecar(path).write_text(json.dumps(state))
    q, saved = recovery.read(path)
    assert [b.name for b in q.blocks] == ["lake"] and q.blocks[0] == p.blocks[1] and saved is None


def test_the_document_owns_the_quality_of_the_final_grid():
    x, y = np.meshgrid(np.arange(6.0), np.arange(5.0), indexing="ij")
    x[2, 2], y[2, 2] = 3.6, 2.9  # a folded node
    g = StructuredGrid(x, y)
    doc = Document()
    seen = []
    doc.quality_changed.connect(lambda: seen.append(doc.quality))
    doc.set_solving(True)
    doc.set_grids({0: g})  # the result arrives while the solve is winding down ...
    assert doc.quality is None
    doc.set_solving(False)  # ... and counts when it has ended
    assert doc.quality is not None and doc.quality.n_folded >= 1 and doc.quality_grid is g
    doc.set_colour_by("skewness")
    grid, values, label = doc.colour_values()
    assert grid is g and label == "skewness" and values is doc.quality.arrays["skewness"]
    doc.set_solving(True)  # a new solve withdraws the old numbers
    assert doc.quality is None and doc.colour_values() == (None, None, "")
    assert [s is None for s in seen] == [False, True]
    with pytest.raises(ValueError, match="unknown metric"):
        doc.set_colour_by("beauty")
