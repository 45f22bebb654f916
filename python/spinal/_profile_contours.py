"""Zero lines of a function sampled on a grid (marching squares), for the parabolic lines of
:class:`spinal.ProfileSurface`: the crossings on the grid's edges between positive and
non-positive samples, chained through the cells they share, and the surface points of such
lines by bilinear interpolation of the sample points."""

from __future__ import annotations

from typing import TypeAlias

import numpy as np

#: An edge of the sample grid: ``("u", i, j)`` from (i, j) to (i+1, j), ``("v", i, j)`` to (i, j+1).
_Edge: TypeAlias = tuple[str, int, int]


def _contours(f: np.ndarray, wrap_v: bool) -> list[tuple[np.ndarray, np.ndarray]]:
    """Zero lines of ``f`` on its grid as ``(i, j)`` fractional index polylines: crossings
    on edges between ``f > 0`` and ``f ≤ 0`` samples, chained through shared edges."""
    nv = f.shape[1]
    inside = f > 0
    cols = nv if wrap_v else nv - 1

    # crossing points, keyed by edge: "u" edges (i, j)-(i+1, j), "v" edges (i, j)-(i, j+1)
    def u_edge(i: int, j: int) -> _Edge:
        return ("u", i, j % nv)

    def v_edge(i: int, j: int) -> _Edge:
        return ("v", i, j % nv)

    def point(key: _Edge) -> tuple[float, float]:
        kind, i, j = key
        if kind == "u":
            a, b = f[i, j], f[i + 1, j]
            return i + a / (a - b), float(j)
        jn = (j + 1) % nv
        a, b = f[i, j], f[i, jn]
        return float(i), j + a / (a - b)

    graph: dict[_Edge, list[_Edge]] = {}

    def link(p: _Edge, q: _Edge) -> None:
        graph.setdefault(p, []).append(q)
        graph.setdefault(q, []).append(p)

    jj = np.arange(cols)
    q = (inside[:-1, jj].astype(int) + inside[1:, jj] + inside[:-1, (jj + 1) % nv]
         + inside[1:, (jj + 1) % nv])
    for i, j in zip(*np.nonzero((q > 0) & (q < 4)), strict=True):
        i, j = int(i), int(j)
        jn = (j + 1) % nv
        c00, c10, c01, c11 = inside[i, j], inside[i + 1, j], inside[i, jn], inside[i + 1, jn]
        e = []  # crossed edges in cyclic order: bottom (j), right (i+1), top (j+1), left (i)
        if c00 != c10:
            e.append(u_edge(i, j))
        if c10 != c11:
            e.append(v_edge(i + 1, j))
        if c01 != c11:
            e.append(u_edge(i, j + 1))
        if c00 != c01:
            e.append(v_edge(i, j))
        if len(e) == 2:
            link(e[0], e[1])
        else:  # a saddle: pair by the mean of the corners
            centre = 0.25 * (f[i, j] + f[i + 1, j] + f[i, jn] + f[i + 1, jn]) > 0
            bottom, right, top, left = e
            if centre == c00:
                link(bottom, right)
                link(top, left)
            else:
                link(bottom, left)
                link(right, top)
    lines = []
    seen: set[_Edge] = set()
    starts = [n for n, nb in graph.items() if len(nb) == 1] + list(graph)
    for start in starts:
        if start in seen:
            continue
        chain = [start]
        seen.add(start)
        prev, cur = None, start
        while True:
            nxt = [q for q in graph[cur] if q != prev and q not in seen]
            if not nxt:
                if len(chain) > 2 and start in graph[cur] and prev is not None:
                    chain.append(start)  # a closed loop
                break
            prev, cur = cur, nxt[0]
            chain.append(cur)
            seen.add(cur)
        if len(chain) >= 2:
            pts = np.array([point(k) for k in chain])
            lines.append((pts[:, 0], pts[:, 1]))
    return lines


def _bilinear(P: np.ndarray, fi: np.ndarray, fj: np.ndarray, wrap: bool) -> np.ndarray:
    nu, nv = P.shape[:2]
    i0 = np.clip(np.floor(fi).astype(int), 0, nu - 2)
    j0 = np.floor(fj).astype(int)
    j0 = j0 % nv if wrap else np.clip(j0, 0, nv - 2)
    a = (fi - i0)[:, None]
    b = (fj - np.floor(fj))[:, None] if wrap else (fj - j0)[:, None]
    j1 = (j0 + 1) % nv
    out: np.ndarray = ((1 - a) * (1 - b) * P[i0, j0] + a * (1 - b) * P[i0 + 1, j0]
            + (1 - a) * b * P[i0, j1] + a * b * P[i0 + 1, j1])
    return out
