"""Level of detail on the canvas: block labels, corners, cut ends and boundary points never cover
a zoomed-out lake; zoomed in, they are all there.  (Generated lakes, never the shipped ones.)"""

from __future__ import annotations

import numpy as np
import pytest

from app import geometry as geo

pytestmark = pytest.mark.gui


def _laid_out(win, seed: int = 5, cells: int = 4000):
    """A random channel network laid out by the app's rule, set as the project's lake (no grid)."""
    from app.lake import Lake, compute_layout
    from meshcore import testing

    poly = testing.channel_network(seed, n_branches=8)
    lake = Lake(outline=np.asarray(poly.exterior.coords)[:-1], target_cells=cells)
    lake = lake.replaced(layout=compute_layout(lake))
    win.lake_ctl.generate_after = False
    win.editor.set_lake(lake, "Auto layout")
    win.canvas.fit()
    return lake.layout


def _nearest_median(p: np.ndarray) -> float:
    """The median distance from each point to its nearest other (brute force: the test's own oracle)."""
    d = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1])
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(axis=1)))


def _label_rects(win) -> list:
    """The scene rectangles of the block labels on screen, with their texts."""
    out = []
    for t in win.canvas.lake_items.labels:
        if t.isVisible() and t.textItem.toPlainText():
            out.append((t.textItem.toPlainText(), t.textItem.sceneBoundingRect()))
    return out


def test_label_levels_place_the_most_detail_that_fits_without_overlap():
    at = np.array([[0.0, 0.0], [1.0, 0.0], [10.0, 0.0]])
    half = np.array([[[2.0, 1.0], [0.6, 0.5]]] * 3)  # a long text and a short one per label
    fits = np.ones((3, 2), bool)
    # the first placed keeps its long text; the second, 1 away, cannot show either; the far one can
    assert list(geo.label_levels(at, half, fits, [0, 1, 2])) == [0, -1, 0]
    # the short text where the long one does not fit its region
    fits[2, 0] = False
    assert list(geo.label_levels(at, half, fits, [2, 1, 0])) == [-1, 0, 1]  # 0 would overlap 1's long text
    assert list(geo.label_levels(at, half, np.zeros((3, 2), bool), [0, 1, 2])) == [-1, -1, -1]


def test_marker_size_shrinks_with_the_spacing_and_hides_below_a_few_pixels():
    assert geo.marker_size(100.0, 8.0) == 8.0 and geo.marker_size(np.inf, 8.0) == 8.0
    sizes = [geo.marker_size(s, 8.0) for s in np.linspace(0.5, 20, 40)]
    assert sizes == sorted(sizes)  # never bigger when closer
    assert all(s == 0 or s <= max(d / 1.5, 8) for s, d in zip(sizes, np.linspace(0.5, 20, 40), strict=True))
    assert geo.marker_size(2.0, 8.0) == 0.0
    pts = np.column_stack([np.arange(10.0), np.zeros(10)])
    assert geo.typical_spacing(pts) == pytest.approx(1.0)
    assert geo.typical_spacing(pts, along=True) == pytest.approx(1.0)
    assert geo.typical_spacing(pts[:1]) == np.inf


def test_block_labels_never_overlap_and_show_on_zoom(qtbot, win):
    """Zoomed out, the labels shown do not overlap and each lies in its block; zoomed onto a block,
    its label shows its name and cells (issue 13: 80 labels covered Kyoga's grid)."""
    from shapely.geometry import Polygon

    lay = _laid_out(win)
    n = len(lay.blocks)
    assert n >= 10
    items = win.canvas.lake_items
    win.canvas.zoom_to(lay.polygon.bounds, margin=0.5)  # the whole lake, small on screen
    rects = _label_rects(win)
    assert len(rects) < n  # not every block has room for a label at this size
    for a in range(len(rects)):
        for b in range(a + 1, len(rects)):
            assert not rects[a][1].intersects(rects[b][1]), (rects[a][0], rects[b][0])
    # each label shown lies inside its block on screen, or covers at most half of it
    vb = win.canvas.getPlotItem().vb
    for k, t in enumerate(items.labels[:n]):
        if not t.isVisible():
            continue
        r = vb.mapSceneToView(t.textItem.sceneBoundingRect()).boundingRect()
        box = Polygon([(r.left(), r.top()), (r.right(), r.top()), (r.right(), r.bottom()), (r.left(), r.bottom())])
        block = Polygon(lay.pieces[k].ring).buffer(1e-9)
        assert block.contains(box.centroid)
        assert block.contains(box) or block.area >= 2 * box.area
    # zoomed onto a block, its label is there with name and cells
    k = int(np.argmin([Polygon(pc.ring).area for pc in lay.pieces]))  # the smallest block
    b = lay.blocks[k]
    text = f"{b.name}\n{b.cells[0]}×{b.cells[1]}"
    x0, y0, x1, y1 = Polygon(lay.pieces[k].ring).bounds
    cx, cy, r = items.labels[k].pos().x(), items.labels[k].pos().y(), max(x1 - x0, y1 - y0)
    for _ in range(8):  # zoom in around the label, as a user would, until it reads in full
        win.canvas.zoom_to((cx - r, cy - r, cx + r, cy + r), margin=0)
        if items.labels[k].isVisible() and items.labels[k].textItem.toPlainText() == text:
            break
        r /= 2
    assert items.labels[k].isVisible() and items.labels[k].textItem.toPlainText() == text
    assert text in items.shown_labels
    # markers hidden: no label; shown again: back as the view allows
    win.a_markers.trigger()
    assert not any(t.isVisible() for t in items.labels) and items.shown_labels == []
    win.a_markers.trigger()
    assert items.labels[k].isVisible()


def test_corners_and_cut_ends_shrink_when_zoomed_out(qtbot, win):
    """The layout's corner squares and cut-end circles never touch on screen: smaller, or hidden,
    when the lake is zoomed out; full size zoomed in."""
    lay = _laid_out(win)
    items = win.canvas.lake_items
    corners = np.unique(np.array([p for b in lay.blocks for p in b.corners], float), axis=0)
    spacing = _nearest_median(corners)
    full = {"corners": 8.0, "cut_ends": 9.0}
    x0, y0, x1, y1 = lay.polygon.bounds
    for zoom in (0.05, 0.3, 1.0, 4.0, 20.0):  # the view shows 1 / zoom lake widths
        w = (x1 - x0) / zoom
        cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        win.canvas.zoom_to((cx - w / 2, cy - w / 2, cx + w / 2, cy + w / 2), margin=0)
        px = win.canvas.pixel()
        for name, size in full.items():
            item = getattr(items, name)
            if item.isVisible():  # full size, or small enough to leave a gap to the nearest corner
                assert item.opts["size"] == size or item.opts["size"] <= spacing / px / 1.5
    win.canvas.zoom_to(lay.polygon.bounds, margin=5.0)
    assert not items.corners.isVisible() or items.corners.opts["size"] < 8.0
    c0 = corners[0]
    win.canvas.zoom_to((c0[0] - spacing, c0[1] - spacing, c0[0] + spacing, c0[1] + spacing))
    assert items.corners.isVisible() and items.corners.opts["size"] == 8.0 and items.cut_ends.opts["size"] == 9.0


def test_dense_boundary_points_are_not_a_black_band(qtbot, win):
    """Thousands of outline points zoomed out: drawn smaller, or hidden (the shore line shows); zoomed
    in, at full size; View ▸ Boundary markers still hides and shows them."""
    t = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    pts = np.column_stack([1000 * np.cos(t), 400 * np.sin(t)])
    from app.project import block_from_points

    win.editor.replace_project(win.doc.project.replaced(blocks=(block_from_points(pts, "oval", total=40),)), "Import")
    c = win.canvas
    c.fit()
    step = float(np.median(np.hypot(*np.diff(pts, axis=0).T)))
    assert step / c.pixel() < 3  # the points are crowded on screen
    assert not c.points_item.isVisible() or c.points_item.opts["size"] <= step / c.pixel()
    c.zoom_to((pts[0, 0] - step, pts[0, 1] - step, pts[0, 0] + step, pts[0, 1] + step))
    assert c.points_item.isVisible() and c.points_item.opts["size"] == 7.0
    win.a_markers.trigger()
    assert not c.points_item.isVisible()
    win.a_markers.trigger()
    assert c.points_item.isVisible()
