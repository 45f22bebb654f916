"""Pappus' volume of closed sweeps with half-integer ``turns`` (docs/accuracy.md).

A profile whose centroid is on the spine sweeps the volume ``2πR·A`` along a circle of
radius R, however it turns about the tangent; the table prints the relative error of the
mesh volume (trimesh) and its order per doubling of the samples.

    PYTHONPATH=python python benchmarks/pappus_half_turns.py
"""

from __future__ import annotations

import numpy as np
import trimesh

import spinal

R = 3.0


def circle(n: int) -> np.ndarray:
    u = 2 * np.pi * np.arange(n) / n
    return np.c_[R * np.cos(u), R * np.sin(u), np.zeros(n)]


def error(n: int, profile: np.ndarray, area: float, turns: float) -> float:
    m = spinal.sweep(circle(n), profile, closed=True, turns=turns)
    volume = trimesh.Trimesh(m.vertices, m.faces, process=False).volume
    return abs(volume - area * 2 * np.pi * R) / (area * 2 * np.pi * R)


def main() -> None:
    a, b = 1.0, 0.5
    rect = np.array([[a, b], [-a, b], [-a, -b], [a, -b]])
    ns = [32, 64, 128, 256, 512]
    for turns in (0, 0.5, 1.5):
        e = np.array([error(n, rect, 4 * a * b, turns) for n in ns])
        print(f"rectangle turns={turns}:", " ".join(f"{x:.3e}" for x in e),
              "orders", np.round(np.log2(e[:-1] / e[1:]), 5))
    e = []
    for n in ns:
        u = 2 * np.pi * np.arange(n // 2) / (n // 2)
        e.append(error(n, np.c_[a * np.cos(u), b * np.sin(u)], np.pi * a * b, 0.5))
    e = np.array(e)
    print("ellipse turns=0.5 (n/2 sides):", " ".join(f"{x:.3e}" for x in e),
          "orders", np.round(np.log2(e[:-1] / e[1:]), 5))


if __name__ == "__main__":
    main()
