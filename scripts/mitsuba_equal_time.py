#!/usr/bin/env python3
"""Mitsuba 3's path tracer on the bench suite's XML scene, for the time-to-error table.

Development tool (needs `pip install mitsuba`; `llvm_ad_rgb` also needs Debian's libllvm19),
never part of CI or of the project's dependencies. Run from the repository root after
`restir bench` has cached its references:

    python3 scripts/mitsuba_equal_time.py [--scene scenes/cornell-box.xml] [--size 128]
        [--reference docs/bench/references/cornell-box-<hash>.exr] [--variant llvm_ad_rgb]

For each pass count it renders once to compile the kernels, then `--seeds` times with different
seeds, and prints the median wall time of `mi.render` (all cores, as `restir bench`) and the
mean relMSE against the same reference `restir bench` uses, with the same metric
(mean over pixels and channels of (x − r)² / (r² + 0.01)).
"""

import argparse
import glob
import statistics
import time

import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="scenes/cornell-box.xml")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--reference", default=None)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--spp", default="4,8,16,32,64,128,256,512")
    a = ap.parse_args()

    import mitsuba as mi
    mi.set_variant(a.variant)
    ref_path = a.reference or sorted(glob.glob("docs/bench/references/cornell-box-*.exr"))[0]
    ref = np.array(mi.Bitmap(ref_path))[..., :3].astype(np.float64)
    scene = mi.load_file(a.scene, resx=a.size, resy=a.size)

    print(f"# Mitsuba {mi.__version__} {a.variant}, {a.scene} at {a.size}x{a.size}, "
          f"reference {ref_path}")
    print("| spp | seconds (median) | relMSE (mean of seeds) | relMSE × seconds |")
    print("|---|---|---|---|")
    for spp in [int(s) for s in a.spp.split(",")]:
        mi.render(scene, spp=spp, seed=10_000)  # compile the kernels for this spp
        times, errs = [], []
        for seed in range(a.seeds):
            t = time.perf_counter()
            img = mi.render(scene, spp=spp, seed=seed)
            img = np.array(img)[..., :3].astype(np.float64)  # forces evaluation
            times.append(time.perf_counter() - t)
            errs.append(float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01))))
        t, e = statistics.median(times), statistics.mean(errs)
        print(f"| {spp} | {t:.3f} | {e:.3e} | {t * e:.4f} |")


if __name__ == "__main__":
    main()
