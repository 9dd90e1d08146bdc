"""NumPy reference of :mod:`._equalize_kernels` (test oracle): the equalize step's objective and its
gradient, vectorised (moved out of :mod:`.equalize` to keep that module short)."""

from __future__ import annotations

import numpy as np

__all__ = ["objective_numpy"]


def _area_grad(P: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed areas of quads ``C`` and their gradients ``(n, 4, 2)`` in the 4 corners."""
    d1 = P[C[:, 2]] - P[C[:, 0]]
    d2 = P[C[:, 3]] - P[C[:, 1]]
    A = 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    g2 = 0.5 * np.column_stack([d2[:, 1], -d2[:, 0]])
    g3 = 0.5 * np.column_stack([-d1[:, 1], d1[:, 0]])
    return A, np.stack([-g2, -g3, g2, g3], axis=1)


def _jacobians_grad(P: np.ndarray, C: np.ndarray):
    """Corner cross products ``(n, 4)`` and their gradients in the next and the previous corner."""
    Q = P[C]
    a = np.roll(Q, -1, axis=1) - Q
    b = np.roll(Q, 1, axis=1) - Q
    J = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    dJa = np.stack([b[..., 1], -b[..., 0]], -1)
    dJb = np.stack([-a[..., 1], a[..., 0]], -1)
    return J, dJa, dJb


def _cos_grad(P: np.ndarray, S: np.ndarray):
    """``|cos|`` at 5-node stencils and its gradient in the two central differences."""
    a = P[S[:, 1]] - P[S[:, 2]]
    b = P[S[:, 3]] - P[S[:, 4]]
    na, nb = np.hypot(*a.T), np.hypot(*b.T)
    d = (a * b).sum(1)
    nn = np.maximum(na * nb, 1e-300)
    c = np.abs(d) / nn
    sd = np.sign(d)[:, None]
    dca = sd * b / nn[:, None] - (c / np.maximum(na, 1e-300) ** 2)[:, None] * a
    dcb = sd * a / nn[:, None] - (c / np.maximum(nb, 1e-300) ** 2)[:, None] * b
    return c, dca, dcb


def _edge_grad(P: np.ndarray, T: np.ndarray):
    """``|log l1/l2|`` of consecutive edges and its gradient in the 3 nodes."""
    v1 = P[T[:, 1]] - P[T[:, 0]]
    v2 = P[T[:, 2]] - P[T[:, 1]]
    q1 = np.maximum((v1 * v1).sum(1), 1e-300)
    q2 = np.maximum((v2 * v2).sum(1), 1e-300)
    u = 0.5 * (np.log(q1) - np.log(q2))
    sg = np.sign(u)[:, None]
    g1 = v1 / q1[:, None]
    g2 = v2 / q2[:, None]
    return np.abs(u), -sg * g1, sg * (g1 + g2), -sg * g2


def objective_numpy(patch, z: np.ndarray, *, AIM: float, W_COS: float, W_JAC: float) -> tuple[float, np.ndarray]:
    """``_Patch.objective`` of :mod:`.equalize` in NumPy for ``patch`` (the compiled
    kernel's reference in the tests), with that module's constants ``AIM``, ``W_COS``, ``W_JAC``."""
    P = patch.positions(z)
    G = np.zeros_like(P)
    C, sg = patch.C, patch.sg
    J, dJa, dJb = _jacobians_grad(P, C)
    J = sg[:, None] * J
    if (J <= 0).any():
        return 1e6, np.zeros_like(z)
    # cross-interface ratios
    T = patch.t.cells
    Ca, Cb = T[patch.pairs[:, 0]], T[patch.pairs[:, 1]]
    Aa, ga = _area_grad(P, Ca)
    Ab, gb = _area_grad(P, Cb)
    u = np.log(np.abs(Aa)) - np.log(np.abs(Ab))
    ex = np.maximum(np.abs(u) - np.log(AIM), 0.0)
    f = float(np.sum(ex**2))
    w = 2 * ex * np.sign(u)
    np.add.at(G, Ca, (w / Aa)[:, None, None] * ga)
    np.add.at(G, Cb, -(w / Ab)[:, None, None] * gb)
    # orthogonality at block-interior nodes
    c, dca, dcb = _cos_grad(P, patch.cos)
    ex = np.maximum(c - patch.c_allowed, 0.0)
    f += W_COS * float(np.sum(ex**2))
    w = (2 * W_COS * ex)[:, None]
    S = patch.cos
    np.add.at(G, S[:, 1], w * dca)
    np.add.at(G, S[:, 2], -w * dca)
    np.add.at(G, S[:, 3], w * dcb)
    np.add.at(G, S[:, 4], -w * dcb)
    # consecutive edges along grid lines
    e, d0, d1, d2 = _edge_grad(P, patch.tri)
    ex = np.maximum(e - patch.e_allowed, 0.0)
    f += patch.w_edge * float(np.sum(ex**2))
    w = (2 * patch.w_edge * ex)[:, None]
    for k, d in enumerate((d0, d1, d2)):
        np.add.at(G, patch.tri[:, k], w * d)
    # corner Jacobians kept above half of theirs
    ex = np.maximum(0.5 - J / patch.J0, 0.0)
    f += W_JAC * float(np.sum(ex**2))
    w = -2 * W_JAC * ex / patch.J0 * sg[:, None]  # d/dJ_raw
    Cn, Cp = np.roll(C, -1, axis=1), np.roll(C, 1, axis=1)
    np.add.at(G, Cn, w[..., None] * dJa)
    np.add.at(G, Cp, w[..., None] * dJb)
    np.add.at(G, C, -w[..., None] * (dJa + dJb))
    gz = patch.chain(G, z)
    return f + 1e-3 * float(z @ z), gz + 2e-3 * z
