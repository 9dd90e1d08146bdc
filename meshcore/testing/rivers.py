"""Rivers, meanders and estuaries (re-exported by :mod:`meshcore.testing`).

The water bodies a river modeller meshes, built from sine-generated centrelines (Langbein and
Leopold 1966: the direction of the channel ``θ(s) = ω sin(2πs / M)`` along its arc length ``s``,
with Kinoshita's skewing and flattening terms ``ω³ (J_s cos 3φ − J_f sin 3φ)``), each bend's ``ω``
and arc wavelength ``M`` varied a little, the width varied along the reach:

* :func:`meander` — a meandering reach 20–80 widths long, ``ω`` up to 110° (nearly cut-off
  loops), bends of centreline radius 1.5–3 widths at their apex, width ±30 %;
* :func:`meander_bars` — the same with 1–4 mid-channel bars (islands elongated along the flow,
  some near a bank), the channel widened round each;
* :func:`confluence` — two meandering rivers joining at 30–90°;
* :func:`estuary` — a funnel whose width grows exponentially to the mouth, closed across the
  mouth, its centreline meandering less as it widens, with a few side creeks.

Both ends of every channel are straight cuts across it (open boundaries).  Widths are in the
units of ``width`` (the river's width at its upstream end); a drawn shape whose loops come within
half a width of each other (or whose inner bank would cusp) is drawn again, ``ω`` a little
smaller, so every seed gives a valid polygon.

>>> from meshcore.testing import meander
>>> p = meander(3)
>>> p.is_valid and p.area > 0
True
"""

from __future__ import annotations

import math

import numpy as np

from ._shapes import _clean


def _smooth_noise(rng, s: np.ndarray, scale: float) -> np.ndarray:
    """A smooth random function of ``s`` in [-1, 1]: three sinusoids of wavelengths about
    ``scale / 2``, ``scale`` and ``3 scale``, random phases, scaled to a largest magnitude of 1."""
    f = np.zeros_like(s)
    for lam, a in ((0.5, 0.3), (1.0, 0.5), (3.0, 1.0)):
        w = lam * scale * rng.uniform(0.8, 1.25)
        f += a * rng.uniform(0.5, 1.0) * np.sin(2 * math.pi * s / w + rng.uniform(0, 2 * math.pi))
    return f / max(float(np.abs(f).max()), 1e-12)


def _path(
    rng,
    length: float,
    *,
    omega: float,
    wavelength,
    ds: float,
    heading: float = 0.0,
    start=(0.0, 0.0),
    phase0: float | None = None,
    irregular: float = 0.2,
):
    """A sine-generated centreline: arc lengths ``s``, points, directions ``θ``.

    ``omega`` (radians) and the arc wavelength (a number, or a function of ``s``) vary by
    ``±irregular`` from bend to bend (knots half a wavelength apart, interpolated);
    Kinoshita's skewing ``J_s`` and flattening ``J_f`` are drawn in ±0.03 and [0, 0.03]."""
    n = max(8, math.ceil(length / ds) + 1)
    s = np.linspace(0.0, length, n)
    m = wavelength(s) if callable(wavelength) else np.full(n, float(wavelength))
    step = 0.5 * float(np.min(m))
    knots = np.arange(0.0, length + 2 * step, step)
    om = omega * np.interp(s, knots, 1.0 - irregular * rng.uniform(0.0, 1.0, len(knots)))
    m = m * np.interp(s, knots, 1.0 + irregular * rng.uniform(-1.0, 1.0, len(knots)))
    rate = 2 * math.pi / m
    phase = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(s))])
    phase += rng.uniform(0, 2 * math.pi) if phase0 is None else phase0
    js, jf = rng.uniform(-0.03, 0.03), rng.uniform(0.0, 0.03)
    theta = heading + om * np.sin(phase) + om**3 * (js * np.cos(3 * phase) - jf * np.sin(3 * phase))
    d = np.column_stack([np.cos(theta), np.sin(theta)])
    xy = np.asarray(start, float) + np.vstack(
        [[0.0, 0.0], np.cumsum(0.5 * (d[1:] + d[:-1]) * np.diff(s)[:, None], axis=0)]
    )
    return s, xy, theta


def _ribbon(xy: np.ndarray, theta: np.ndarray, half: np.ndarray):
    """The polygon between the banks ``xy ± half · normal(θ)``, flat across both ends."""
    from shapely.geometry import Polygon

    nrm = np.column_stack([-np.sin(theta), np.cos(theta)])
    left = xy + nrm * half[:, None]
    right = xy - nrm * half[:, None]
    return Polygon(np.vstack([right, left[::-1]]))


def _fits(s: np.ndarray, xy: np.ndarray, theta: np.ndarray, half: np.ndarray, gap: float) -> bool:
    """Banks that neither cusp (half-width under 0.8 of the centreline's radius of curvature)
    nor come within ``gap`` of another part of the channel (a loop's neck)."""
    kappa = np.abs(np.gradient(np.unwrap(theta), s))
    if np.any(kappa * half > 0.8):
        return False
    sub = slice(None, None, max(1, len(s) // 1500))
    p, q, hh = xy[sub], s[sub], half[sub]
    d = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1])
    near = hh[:, None] + hh[None, :] + gap
    apart = np.abs(q[:, None] - q[None, :]) > 1.5 * near  # not neighbours along the channel
    return not np.any(apart & (d < near))


def _reach(rng, width: float, length, omega, variation: float, neck: float, ds: float):
    """A meandering reach: ``(s, xy, θ, half)`` and its polygon, drawn until it fits."""
    L = width * (rng.uniform(*length) if isinstance(length, tuple) else float(length))
    om = math.radians(rng.uniform(*omega) if isinstance(omega, tuple) else float(omega))
    heading = rng.uniform(0, 2 * math.pi)
    for attempt in range(60):
        rc = width * rng.uniform(1.5, 3.0)  # centreline radius at a bend's apex, in widths
        M = 2 * math.pi * om * rc
        s, xy, theta = _path(rng, L, omega=om, wavelength=max(M, 4 * width), ds=ds, heading=heading)
        half = 0.5 * width * (1.0 + rng.uniform(0.5, 1.0) * variation * _smooth_noise(rng, s, max(M, 4 * width)))
        poly = _ribbon(xy, theta, half)
        if poly.is_valid and _fits(s, xy, theta, half, neck * width):
            return s, xy, theta, half, poly
        if attempt % 3 == 2:
            om *= 0.93
    raise RuntimeError("no meander fits")  # pragma: no cover (ω shrinks to a nearly straight reach)


def meander(
    seed: int,
    *,
    width: float = 1.0,
    length: float | tuple[float, float] = (20.0, 80.0),
    omega: float | tuple[float, float] = (30.0, 110.0),
    variation: float = 0.3,
    neck: float = 0.5,
):
    """A meandering river reach ``length`` widths long (centreline) and ``width`` wide upstream.

    A sine-generated centreline (``omega``: the largest angle to the valley axis in degrees,
    110° makes loops nearly cut off; the arc wavelength such that a bend's apex has a
    centreline radius of 1.5–3 widths), the width varied smoothly by up to ``±variation``; no
    two loops closer than ``neck`` widths.  Both ends are cut straight across.
    """
    rng = np.random.default_rng(seed)
    *_, poly = _reach(rng, width, length, omega, variation, neck, width / 16)
    return _clean(poly)


def _frame(s, xy, theta):
    """Point and normal of a centreline at arc length ``t`` (linear interpolation)."""

    def at(t: np.ndarray):
        th = np.interp(t, s, np.unwrap(theta))
        p = np.column_stack([np.interp(t, s, xy[:, 0]), np.interp(t, s, xy[:, 1])])
        return p, np.column_stack([-np.sin(th), np.cos(th)])

    return at


def meander_bars(
    seed: int,
    *,
    n_bars: int | None = None,
    width: float = 1.0,
    length: float | tuple[float, float] = (20.0, 80.0),
    omega: float | tuple[float, float] = (30.0, 110.0),
    bar_width: tuple[float, float] = (0.3, 0.55),
    elongation: tuple[float, float] = (2.5, 6.0),
):
    """A meandering reach (:func:`meander`) with ``n_bars`` (default 1–4) mid-channel bars.

    Each bar is an island ``bar_width`` widths across and ``elongation`` times as long, lying
    along the flow (it bends with the channel), blunt upstream and tapering downstream.  Half of
    them sit mid-channel, the others 0.08–0.2 widths from a bank (a narrow side channel); the
    channel is widened by the bar's width over the bar and a width either side, so the water
    beside a mid-channel bar is half a width on each side.
    """
    from shapely.geometry import Polygon

    rng = np.random.default_rng(seed)
    want = int(rng.integers(1, 5)) if n_bars is None else int(n_bars)
    for attempt in range(20):
        s, xy, theta, half, _ = _reach(rng, width, length, omega, 0.3, 0.5 + bar_width[1], width / 16)
        L = float(s[-1])
        bars: list[tuple[float, float, float, float, bool]] = []  # centre s, length, width, offset, near a bank
        for _ in range(40 * want):
            if len(bars) == want:
                break
            bw = width * rng.uniform(*bar_width)
            bl = bw * rng.uniform(*elongation)
            c = rng.uniform(3 * width + bl / 2, L - 3 * width - bl / 2) if 6 * width + bl < L else None
            if c is None or any(abs(c - b[0]) < (bl + b[1]) / 2 + 2 * width for b in bars):
                continue
            side = rng.choice([-1.0, 1.0])
            bank = rng.uniform() < 0.5
            off = side * width * (rng.uniform(0.08, 0.2) if bank else rng.uniform(0.0, 0.08))
            bars.append((c, bl, bw, off, bank))
        widened = half.copy()
        for c, bl, bw, _, _ in bars:
            t = np.clip((np.abs(s - c) - bl / 2) / width, 0.0, 1.0)  # 0 over the bar, 1 a width away
            widened += 0.5 * bw * 0.5 * (1 + np.cos(math.pi * t))
        water = _ribbon(xy, theta, widened)
        if not (water.is_valid and _fits(s, xy, theta, widened, 0.5 * width)):
            continue
        at = _frame(s, xy, theta)
        holes = []
        for c, bl, bw, off, bank in bars:
            u = np.linspace(0.0, 1.0, 40)
            thick = 0.5 * bw * np.sin(math.pi * u**0.75) ** 0.6  # blunt head (u = 0 upstream), long tail
            t = c - bl / 2 + bl * u
            hw = np.interp(t, s, widened)
            if bank:  # the gap |off| measured from the bank
                mid = np.sign(off) * (hw - abs(off) - 0.5 * bw)
            else:
                mid = np.full_like(u, off)
            p, nrm = at(t)
            ring = np.vstack([p + nrm * (mid + thick)[:, None], (p + nrm * (mid - thick)[:, None])[::-1]])
            holes.append(Polygon(ring).buffer(0))
        body = water.buffer(-0.05 * width)
        if all(h.is_valid and body.contains(h) for h in holes) or attempt == 19:
            return _clean(Polygon(water.exterior, [h.exterior for h in holes if body.contains(h)]))
    raise RuntimeError("unreachable")  # pragma: no cover


def confluence(
    seed: int,
    *,
    width: float = 1.0,
    length: float | tuple[float, float] = (30.0, 70.0),
    tributary: tuple[float, float] = (0.4, 0.8),
    tributary_length: tuple[float, float] = (15.0, 40.0),
    angle: tuple[float, float] = (30.0, 90.0),
    omega: float | tuple[float, float] = (30.0, 100.0),
):
    """Two meandering rivers joining: a main reach (:func:`meander`, ``length`` widths) and a
    tributary ``tributary`` times as wide, ``tributary_length`` of its own widths long, that meets
    the main channel in its middle third, its flow at ``angle`` degrees to the main flow (either
    bank).  The tributary stays half a main width clear of the main channel away from the
    junction; a draw that does not is made again."""
    import shapely
    from shapely.geometry import Point

    rng = np.random.default_rng(seed)
    s, xy, theta, half, main = _reach(rng, width, length, omega, 0.3, 0.5, width / 16)
    at = _frame(s, xy, theta)
    for attempt in range(80):
        wt = width * rng.uniform(*tributary)
        c = rng.uniform(0.3, 0.7) * s[-1]
        p, nrm = at(np.array([c]))
        down = np.array([nrm[0, 1], -nrm[0, 0]])  # the main flow's direction there
        a = math.radians(rng.uniform(*angle)) * rng.choice([-1.0, 1.0])
        up = -np.array([down[0] * math.cos(a) - down[1] * math.sin(a), down[0] * math.sin(a) + down[1] * math.cos(a)])
        om = math.radians(rng.uniform(*omega) if isinstance(omega, tuple) else float(omega)) * 0.97 ** (attempt // 4)
        rc = wt * rng.uniform(1.5, 3.0)
        Lt = wt * rng.uniform(*tributary_length)
        ts, txy, tth = _path(
            rng, Lt, omega=om, wavelength=max(2 * math.pi * om * rc, 4 * wt), ds=wt / 16,
            heading=math.atan2(up[1], up[0]), start=p[0], phase0=0.0,
        )  # fmt: skip
        th = 0.5 * wt * (1.0 + 0.2 * _smooth_noise(rng, ts, 8 * wt))
        trib = _ribbon(txy, tth, th)
        if not (trib.is_valid and _fits(ts, txy, tth, th, 0.5 * wt)):
            continue
        away = trib.difference(Point(p[0]).buffer(2.0 * (half.max() + wt)))
        if away.is_empty or away.distance(main) < 0.5 * width:
            continue
        water = shapely.union_all([main, trib])
        if water.geom_type == "Polygon" and water.is_valid:
            return _clean(water)
    return _clean(main)  # pragma: no cover (no tributary fits: the main reach alone)


def estuary(
    seed: int,
    *,
    n_creeks: int | None = None,
    width: float = 1.0,
    length: tuple[float, float] = (30.0, 60.0),
    ratio: tuple[float, float] = (8.0, 25.0),
    omega: tuple[float, float] = (10.0, 40.0),
    creek_width: tuple[float, float] = (0.5, 1.2),
    creek_length: tuple[float, float] = (5.0, 12.0),
):
    """An estuary: a funnel ``length`` head widths long whose width grows exponentially from
    ``width`` at its head to ``ratio`` times that at the mouth (convergence length
    ``length / ln ratio``), closed by a straight line across the mouth; its centreline meanders
    (``omega`` degrees, arc wavelength 12–16 local widths, so the bends straighten out as it
    widens) and ``n_creeks`` (default 2–5) tidal creeks ``creek_width`` head widths wide and
    ``creek_length`` head widths long, tapering to half their width, leave its banks at 50–130°
    to the seaward direction, meandering themselves; no creek within half a head width of
    another or of the estuary away from its mouth."""
    import shapely
    from shapely.geometry import Point

    rng = np.random.default_rng(seed)
    L = width * rng.uniform(*length)
    k = math.log(rng.uniform(*ratio)) / L
    m = rng.uniform(12.0, 16.0)
    om0 = math.radians(rng.uniform(*omega))
    for attempt in range(60):
        s, xy, theta = _path(
            rng, L, omega=om0 * 0.93 ** (attempt // 3),
            wavelength=lambda t: m * width * np.exp(k * t), ds=width / 8, heading=rng.uniform(0, 2 * math.pi),
        )  # fmt: skip
        half = 0.5 * width * np.exp(k * s) * (1.0 + 0.08 * _smooth_noise(rng, s, 6 * width))
        funnel = _ribbon(xy, theta, half)
        if funnel.is_valid and _fits(s, xy, theta, half, 0.5 * width):
            break
    at = _frame(s, xy, theta)
    want = int(rng.integers(2, 6)) if n_creeks is None else int(n_creeks)
    creeks: list = []
    for _ in range(30 * want):
        if len(creeks) == want:
            break
        c = rng.uniform(0.1, 0.85) * L
        side = rng.choice([-1.0, 1.0])
        wc = width * rng.uniform(*creek_width)
        p, nrm = at(np.array([c]))
        hw = float(np.interp(c, s, half))
        start = p[0] + side * nrm[0] * max(hw - 0.5 * wc, 0.0)
        down = np.array([nrm[0, 1], -nrm[0, 0]])
        b = math.radians(rng.uniform(50.0, 130.0)) * side  # from the seaward direction towards that bank
        d = np.array([down[0] * math.cos(b) - down[1] * math.sin(b), down[0] * math.sin(b) + down[1] * math.cos(b)])
        if np.dot(d, side * nrm[0]) <= 0:
            d = -d
        Lc = width * rng.uniform(*creek_length)
        om = math.radians(rng.uniform(20.0, 70.0))
        cs, cxy, cth = _path(
            rng, Lc, omega=om, wavelength=max(2 * math.pi * om * wc * rng.uniform(1.5, 3.0), 4 * wc),
            ds=wc / 12, heading=math.atan2(d[1], d[0]), start=start, phase0=0.0,
        )  # fmt: skip
        ch = 0.5 * wc * (1.0 - 0.5 * cs / Lc)
        creek = _ribbon(cxy, cth, ch)
        if not (creek.is_valid and _fits(cs, cxy, cth, ch, 0.3 * wc)):
            continue
        away = creek.difference(Point(start).buffer(1.5 * wc + 0.5 * width))
        if away.is_empty or away.distance(funnel) < 0.5 * width:
            continue
        if any(creek.distance(o) < 0.5 * width for o in creeks):
            continue
        creeks.append(creek)
    water = shapely.union_all([funnel, *creeks])
    return _clean(water)
