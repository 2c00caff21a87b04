#!/usr/bin/env python3
"""Renders a Mitsuba 3 reference of a scene in `scenes/` (development cross-check only; not CI).

    python3 docs/validation/mitsuba_reference.py SCENE.xml OUT_DIR --passes 16 --spp 1024 \
        [--variant llvm_ad_rgb] [--first-seed 1000]

Renders `passes` independent images of `spp` samples each (seeds first_seed, first_seed+1, ...),
writes each as OUT_DIR/pass_SEED.exr, and, after every pass, the running mean of all passes
(OUT_DIR/ref.exr) and of its even and odd passes (OUT_DIR/half_a.exr, half_b.exr), so that the
reference's own noise can be estimated (relMSE(half_a, half_b) / 4 is the full mean's share).
Interrupting it leaves a usable reference of the passes done so far.
"""
import argparse
import os
import time

import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--passes", type=int, default=16)
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--first-seed", type=int, default=1000)
    ap.add_argument("-D", action="append", default=[], help="name=value scene parameter")
    args = ap.parse_args()

    import mitsuba as mi

    mi.set_variant(args.variant)
    params = dict(kv.split("=", 1) for kv in args.D)
    scene = mi.load_file(args.scene, **params)
    os.makedirs(args.out, exist_ok=True)
    halves = [[], []]
    for i in range(args.passes):
        seed = args.first_seed + i
        t0 = time.time()
        img = np.array(mi.render(scene, spp=args.spp, seed=seed), dtype=np.float64)[..., :3]
        dt = time.time() - t0
        mi.Bitmap(img.astype(np.float32)).write(os.path.join(args.out, f"pass_{seed}.exr"))
        halves[i % 2].append(img)
        full = np.mean(halves[0] + halves[1], axis=0)
        mi.Bitmap(full.astype(np.float32)).write(os.path.join(args.out, "ref.exr"))
        if halves[1]:
            for name, h in (("half_a", halves[0]), ("half_b", halves[1])):
                mi.Bitmap(np.mean(h, axis=0).astype(np.float32)).write(
                    os.path.join(args.out, f"{name}.exr"))
        print(f"pass {i + 1}/{args.passes} seed {seed}: {dt:.1f} s, mean {full.mean(axis=(0, 1))}",
              flush=True)


if __name__ == "__main__":
    main()
