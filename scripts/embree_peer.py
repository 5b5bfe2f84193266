#!/usr/bin/env python3
"""Peer benchmark: Embree's single-ray occlusion query (through the `embreex` binding) on the
exact rays the reference casts for a scene (`bunny` by default).

    cargo xtask bench --export-rays          # writes out/bench/bunny-{rays,triangles}.bin
    pip install embreex numpy
    python3 scripts/embree_peer.py out/bench

Any built-in or corpus scene, with the reference's own rates printed beside:

    cargo run --release -p shadow-ref --example query_bench -- SCENE 160 120 /tmp/peer
    python3 scripts/embree_peer.py /tmp/peer SCENE

The rays are (origin, unit direction, length) in f32; Embree gets the length as `tfar`. The
script prints rays per second on one thread (best of five) and the occluded share, to compare
with the `occlusion query alone` line of `cargo xtask bench`.
"""
import os
import sys
import time

import numpy as np
from embreex import rtcore_scene as rtcs
from embreex.mesh_construction import TriangleMesh


def main() -> None:
    d = sys.argv[1] if len(sys.argv) > 1 else "out/bench"
    name = sys.argv[2] if len(sys.argv) > 2 else "bunny"
    rays = np.fromfile(os.path.join(d, f"{name}-rays.bin"), dtype="<f4").reshape(-1, 7)
    tris = np.fromfile(os.path.join(d, f"{name}-triangles.bin"), dtype="<f4").reshape(-1, 3, 3)
    scene = rtcs.EmbreeScene()
    TriangleMesh(scene, np.ascontiguousarray(tris))
    o = np.ascontiguousarray(rays[:, 0:3])
    v = np.ascontiguousarray(rays[:, 3:6])
    t = np.ascontiguousarray(rays[:, 6])
    scene.run(o[:1000], v[:1000], dists=t[:1000], query="OCCLUDED")  # warm-up
    best = float("inf")
    hits = None
    for _ in range(5):
        t0 = time.perf_counter()
        hits = scene.run(o, v, dists=t, query="OCCLUDED")
        best = min(best, time.perf_counter() - t0)
    occluded = float(np.mean(hits != -1))
    print(f"embree (embreex) one thread: {len(rays) / best / 1e6:.2f} M occlusion rays/s on {len(rays)} rays, "
          f"{100 * occluded:.1f}% occluded")


if __name__ == "__main__":
    main()
