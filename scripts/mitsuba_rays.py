#!/usr/bin/env python3
"""Ray throughput of our BVH against Mitsuba 3's (Embree, through its vectorised variant) on
the same rays, one thread each.

Development tool: needs `pip install mitsuba numpy` (`llvm_ad_rgb` also needs Debian's
libllvm19); never part of CI or of the project's dependencies.

Each scene is written as Mitsuba 3 XML by `restir convert` (into a temporary directory) and
both sides load that file, so they trace the same geometry. Mitsuba makes the rays, as the
`bvh` micro-benchmarks do: the camera rays through the centres of a 64×64 image (`camera`),
rays in uniformly random directions from those rays' hits (`incoherent`), and shadow rays
between random pairs of hits (`shadow`, any hit ends the ray; pairs whose segment lies in
either surface's plane are left out, as rounding decides those), each set repeated to
`--rays` rays (the shadow set a little fewer). Mitsuba traces them with `ray_intersect_preliminary` and `ray_test` (whole
sets as one kernel, its packets as wide as the CPU allows), we with `Accel::intersect` and
`Accel::occluded` one ray at a time (`crates/bench/examples/ray_file.rs`). Timings are
wall-clock on one thread each, interleaved: every round times Mitsuba on each set (the
median of `--repeats` passes, after a compiling pass) and then runs our program (the same).
Prints per scene and set the medians over rounds in nanoseconds per ray, the rays hit or
occluded on each side (a check that the work is the same), and our throughput over
Mitsuba's.

    cargo build --release -p restir -p restir-bench --example ray_file
    python3 scripts/mitsuba_rays.py --bin target/release/restir \\
        --ray-file target/release/examples/ray_file scenes/cornell-box.xml
"""

import argparse
import os
import statistics
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np


def parse():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--bin", required=True, help="the restir binary (for `restir convert`)")
    p.add_argument("--ray-file", required=True, help="the ray_file example binary")
    p.add_argument("--rays", type=int, default=65536, help="rays per set (default 65536)")
    p.add_argument("--repeats", type=int, default=5, help="passes per timing (median)")
    p.add_argument("--rounds", type=int, default=5, help="interleaved rounds (median)")
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("scenes", nargs="+")
    return p.parse_args()


def rays_of(mi, scene, n, rng):
    """The three ray sets, each (origins, directions, t_max) as numpy arrays."""
    side = 64
    sensor = scene.sensors()[0]
    idx = np.arange(side * side)
    pos = mi.Point2f((idx % side + 0.5) / side, (idx // side + 0.5) / side)
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    si = scene.ray_intersect(ray)
    o, d = np.array(ray.o).T, np.array(ray.d).T
    valid = np.array(si.is_valid())
    p, nrm = np.array(si.p).T[valid], np.array(si.n).T[valid]
    if len(p) == 0:
        sys.exit("no camera ray hits the scene")
    reps = -(-n // len(o))
    camera = (np.tile(o, (reps, 1))[:n], np.tile(d, (reps, 1))[:n], np.full(n, np.inf))
    m = len(p)
    k = rng.integers(0, m, n)
    u = rng.random((n, 2))
    z = 1 - 2 * u[:, 0]
    r = np.sqrt(np.maximum(0.0, 1 - z * z))
    phi = 2 * np.pi * u[:, 1]
    dr_ = np.stack([r * np.cos(phi), r * np.sin(phi), z], 1)
    eps = 1e-4 * max(1.0, float(np.abs(p).max()))

    def offset(at, normal, dirs):
        side_ = np.sign(np.sum(dirs * normal, 1))[:, None]
        return at + eps * side_ * normal

    incoherent = (offset(p[k], nrm[k], dr_), dr_, np.full(n, np.inf))
    j = rng.integers(0, m, n)
    to = p[j] - p[k]
    dist = np.linalg.norm(to, axis=1)
    dirs = to / np.maximum(dist, 1e-30)[:, None]
    # Pairs apart, the segment not in either surface's plane (a ray along a floor between two
    # of its points is decided by rounding, and no renderer aims a shadow ray that way).
    keep = (dist > 1e-3 * max(1.0, float(np.abs(p).max()))) \
        & (np.abs(np.sum(dirs * nrm[k], 1)) > 1e-2) & (np.abs(np.sum(dirs * nrm[j], 1)) > 1e-2)
    k, dirs, dist = k[keep], dirs[keep], dist[keep]
    shadow = (offset(p[k], nrm[k], dirs), dirs, dist * (1 - 1e-3))
    return {"camera": camera, "incoherent": incoherent, "shadow": shadow}


def to_mitsuba(mi, o, d, t):
    ray = mi.Ray3f(mi.Point3f(*o.T.astype(np.float32)), mi.Vector3f(*d.T.astype(np.float32)))
    return mi.Ray3f(ray, mi.Float(np.minimum(t, 3.4e38).astype(np.float32)))


def time_mitsuba(dr, query, ray, repeats):
    out = query(ray)
    dr.eval(out)
    dr.sync_thread()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        out = query(ray)
        dr.eval(out)
        dr.sync_thread()
        times.append(time.perf_counter() - start)
    return statistics.median(times), out


def main():
    a = parse()
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(a.variant)
    rng = np.random.default_rng(a.seed)
    work = tempfile.mkdtemp(prefix="mitsuba-rays-")
    print(f"Mitsuba {mi.__version__} {a.variant}; one thread each; wall-clock ns per ray, "
          f"medians of {a.rounds} interleaved rounds of {a.repeats} passes")
    for path in a.scenes:
        name = os.path.splitext(os.path.basename(path))[0]
        xml = os.path.join(work, name + ".xml")
        subprocess.run([a.bin, "convert", path, "-o", xml], check=True,
                       stdout=subprocess.DEVNULL)
        # Loaded on the default pool (loading an environment map on a one-thread pool hangs
        # in Mitsuba 3.9.1), traced on one thread.
        dr.set_thread_count(os.cpu_count())
        scene = mi.load_file(xml, resx=64, resy=64)
        dr.set_thread_count(1)
        sets = rays_of(mi, scene, a.rays, rng)
        raw = os.path.join(work, name + ".rays")
        with open(raw, "wb") as f:
            for key in ("camera", "incoherent", "shadow"):
                o, d, t = sets[key]
                rows = np.concatenate([o, d, np.minimum(t, 3.4e38)[:, None]], 1)
                f.write(struct.pack("<I", len(rows)))
                f.write(rows.astype("<f4").tobytes())
        mi_rays = {k: to_mitsuba(mi, *v) for k, v in sets.items()}
        ours_ns, mi_ns, counts = {}, {}, {}
        for _ in range(a.rounds):
            for key, ray in mi_rays.items():
                if key == "shadow":
                    sec, out = time_mitsuba(dr, scene.ray_test, ray, a.repeats)
                    hits = int(np.array(out).sum())
                else:
                    sec, out = time_mitsuba(
                        dr, lambda r: scene.ray_intersect_preliminary(r).t, ray, a.repeats)
                    hits = int(np.isfinite(np.array(out)).sum())
                mi_ns.setdefault(key, []).append(sec * 1e9 / len(sets[key][2]))
                counts[key] = [hits]
            run = subprocess.run([a.ray_file, xml, raw, str(a.repeats)], check=True,
                                 capture_output=True, text=True)
            for line in run.stdout.splitlines():
                key, hits, ns = line.split()
                ours_ns.setdefault(key, []).append(float(ns))
                counts[key].append(hits)
        print(f"\n{name}")
        print(f"  {'set':<11} {'Mitsuba ns':>10} {'ours ns':>8} {'ours/Mitsuba':>12}"
              f"  hit or occluded (Mitsuba, ours)")
        for key in ("camera", "incoherent", "shadow"):
            m, o = statistics.median(mi_ns[key]), statistics.median(ours_ns[key])
            print(f"  {key:<11} {m:>10.1f} {o:>8.1f} {m / o:>11.2f}x  {counts[key][0]}, "
                  f"{counts[key][1]}")


if __name__ == "__main__":
    main()
