"""Scale-out with Dask: a bundle of streamline tubes and a deformation animation mapped over
chunks on a ``distributed.LocalCluster`` of worker processes (one thread each, by
``spinal.threads(1)``), checked against the single call, with the throughput per worker.

    python benchmarks/scale_out.py                       # 100,000 curves, 1,000 frames
    python benchmarks/scale_out.py --curves 8000 --frames 60 --chunks 4

Needs ``pip install '.[dask]'``. The tasks carry only seeds or a vertex slice; each returns a
digest of its result and its own compute time. The single call (one process, all threads)
computes the same bundle and animation, and every chunk's part of it must have the chunk's
digest. The same code as ``notebooks/07_scale_out.ipynb``; see ``docs/scale-out.md``.
"""

from __future__ import annotations

import argparse
import hashlib
import time

import numpy as np

import spinal

PER_SEED = 500  # curves made from one seed
SIDES = 6


def bundle(seed: int, n_curves: int, n_points: int = 48):
    """``n_curves`` helical streamlines of a vortex from a seed: flat points and lengths."""
    rng = np.random.default_rng(seed)
    r = rng.uniform(0.2, 2.0, (n_curves, 1))
    phase = rng.uniform(0, 2 * np.pi, (n_curves, 1))
    z0 = rng.uniform(-1, 1, (n_curves, 1))
    s = np.linspace(0, 1, n_points)
    angle = phase + 2.0 * s / np.sqrt(r)
    points = np.stack([r * np.cos(angle), r * np.sin(angle), z0 + 0.8 * s + 0 * r], axis=-1)
    return points.reshape(-1, 3), np.full(n_curves, n_points)


def digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


def tubes(seeds) -> spinal.Mesh:
    points, lengths = zip(*(bundle(s, PER_SEED) for s in seeds))
    return spinal.tube(np.concatenate(points), 0.004, sides=SIDES,
                       lengths=np.concatenate(lengths))


def tube_chunk(seeds) -> dict:
    """One task: the tubes of the curves made from ``seeds``, on one thread."""
    with spinal.threads(1):
        clock = time.perf_counter()
        mesh = tubes(seeds)
        seconds = time.perf_counter() - clock
        threads = spinal.get_num_threads()
    return {"curves": PER_SEED * len(seeds), "threads": threads, "vertices": len(mesh.vertices),
            "faces": len(mesh.faces), "digest": digest(mesh.vertices, mesh.faces),
            "seconds": seconds}


def ring_and_tool():
    t = 2 * np.pi * np.arange(256) / 256
    ring = spinal.tube(np.c_[np.cos(t), np.sin(t), 0 * t], 0.25, sides=64, closed=True)
    tool = spinal.fields.translation([1.6, 0, 0], 0.3, [-0.5, 0, 0])
    return ring, tool


def animate(V, tool, n_frames: int, chunks=None):
    """``n_frames`` frames, each advancing the last by ``0.4 / n_frames`` (4 RK4 steps): a
    digest of every chunk's rows over all frames, and the last frame."""
    dt = 0.4 / n_frames
    parts = chunks or [slice(None)]
    hashes = [hashlib.sha256() for _ in parts]
    for k in range(n_frames):
        V = spinal.advect(V, tool, dt, steps=4, t0=k * dt)
        for h, part in zip(hashes, parts):
            h.update(V[part].tobytes())
    return [h.hexdigest()[:16] for h in hashes], V


def animate_chunk(V, tool, n_frames: int):
    with spinal.threads(1):
        clock = time.perf_counter()
        (h,), last = animate(V, tool, n_frames)
        return h, last, time.perf_counter() - clock


def run(client, n_curves: int, n_frames: int, chunks: int, check: bool = True) -> dict:
    """Both jobs on ``client``; returns the digests, times and throughputs (and raises if a
    chunk differs from the single call when ``check``)."""
    import dask
    import dask.bag as db

    workers = len(client.scheduler_info()["workers"])
    seeds = np.arange(n_curves // PER_SEED)
    split = [c.tolist() for c in np.array_split(seeds, chunks)]
    clock = time.perf_counter()
    results = db.from_sequence(split, npartitions=chunks).map(tube_chunk).compute()
    out = {"workers": workers, "tube_wall": time.perf_counter() - clock, "tube_chunks": results}
    if check:
        clock = time.perf_counter()
        mesh = tubes(seeds)
        out["tube_single"] = time.perf_counter() - clock
        v0 = f0 = 0
        for r in results:
            nv, nf = r["vertices"], r["faces"]
            assert digest(mesh.vertices[v0:v0 + nv], mesh.faces[f0:f0 + nf] - v0) == r["digest"]
            v0, f0 = v0 + nv, f0 + nf
        assert v0 == len(mesh.vertices) and f0 == len(mesh.faces)
        del mesh

    ring, tool = ring_and_tool()
    parts = np.array_split(np.arange(len(ring.vertices)), chunks)
    task = dask.delayed(animate_chunk)
    clock = time.perf_counter()
    frames = dask.compute(*[task(ring.vertices[p], tool, n_frames) for p in parts])
    out.update(anim_wall=time.perf_counter() - clock, anim_chunks=frames,
               anim_vertices=len(ring.vertices))
    if check:
        clock = time.perf_counter()
        hashes, last = animate(ring.vertices, tool, n_frames,
                               chunks=[slice(p[0], p[-1] + 1) for p in parts])
        out["anim_single"] = time.perf_counter() - clock
        assert hashes == [h for h, _, _ in frames]
        assert np.array_equal(last, np.concatenate([v for _, v, _ in frames]))
        out["volume_change"] = spinal.Mesh(last, ring.faces).volume / ring.volume - 1
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--curves", type=int, default=100_000)
    ap.add_argument("--frames", type=int, default=1_000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--chunks", type=int, default=8)
    ap.add_argument("--no-check", action="store_true", help="skip the single call")
    a = ap.parse_args(argv)
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                      dashboard_address=None, silence_logs=50) as cluster, \
            Client(cluster) as client:
        out = run(client, a.curves, a.frames, a.chunks, check=not a.no_check)
    tube_cpu = sum(r["seconds"] for r in out["tube_chunks"])
    anim_cpu = sum(s for _, _, s in out["anim_chunks"])
    steps = out["anim_vertices"] * a.frames * 4
    print(f"{out['workers']} worker processes x 1 thread, {a.chunks} chunks")
    print(f"tubes: {a.curves:,} curves x 48 points, {SIDES} sides: wall {out['tube_wall']:.1f} s; "
          f"per worker {a.curves / tube_cpu:,.0f} curves/s")
    if "tube_single" in out:
        print(f"  single call (all threads): {out['tube_single']:.1f} s; every chunk equal")
    print(f"animation: {a.frames:,} frames of {out['anim_vertices']:,} vertices: wall "
          f"{out['anim_wall']:.1f} s; per worker {steps / anim_cpu / 1e6:.1f} M vertex-steps/s")
    if "anim_single" in out:
        print(f"  single call (all threads): {out['anim_single']:.1f} s; every frame equal; "
              f"volume change {out['volume_change']:+.1e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
