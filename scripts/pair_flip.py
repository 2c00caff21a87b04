#!/usr/bin/env python3
"""FLIP and squared error at equal CPU time, against references, for renders `pair_variance.py` kept.

Development tool. `pair_variance.py` measures variance without a reference, which FLIP cannot
do. For every scene with a reference `REFS/NAME.exr` (a converged render at the same size), this
takes configuration `--label`'s two renders from a `pair_variance.py` output directory, renders
the baseline configuration (`--base-flags`, the path tracer by default) with as many passes as
the label's CPU time buys at the baseline's CPU time per pass (both from the kept stats, loading
excluded), with the same two seeds, and prints the mean over the seeds of `restir compare`'s
FLIP, MSE, relMSE and top-1 % share for both, and their ratios (label / baseline: below 1 the
label is better). The baseline renders are kept in the same directory, so a rerun only compares.

    python3 scripts/pair_flip.py --bin target/release/restir --pv PV --refs REFS \\
        --scenes FAMILY --label pt --base path --base-passes 16 --size 640x360 --threads 1
"""

import argparse
import glob
import json
import os
import statistics
import subprocess


def cpu_seconds(render):
    with open(render + ".json") as f:
        stats = json.load(f)
    return stats["cpu_seconds"] - stats.get("load_seconds", 0.0)


def compare(binary, image, reference):
    out = subprocess.run(
        [binary, "compare", image, reference], capture_output=True, text=True, check=True
    ).stdout
    return {k: float(v) for k, v in (t.split("=") for t in out.split())}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", default="target/release/restir")
    ap.add_argument("--pv", required=True, help="a pair_variance.py output directory")
    ap.add_argument("--refs", required=True, help="references, REFS/NAME.exr per scene")
    ap.add_argument("--scenes", required=True, help="the directory holding NAME.ron or NAME.xml")
    ap.add_argument("--label", default="pt", help="the configuration judged")
    ap.add_argument("--base", default="path", help="the baseline's label in the PV directory")
    ap.add_argument("--base-passes", type=int, default=16, help="its pass count there")
    ap.add_argument("--base-flags", default="--integrator path")
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--threads", default="1")
    ap.add_argument("--seeds", default="11,12")
    a = ap.parse_args()
    width, height = a.size.split("x")
    seeds = [int(s) for s in a.seeds.split(",")]
    keys = ("flip", "mse", "relmse", "top1_share")
    ratios = []
    for reference in sorted(glob.glob(os.path.join(a.refs, "*.exr"))):
        name = os.path.basename(reference)[:-4]
        scene = next(iter(glob.glob(os.path.join(a.scenes, name + ".*"))), None)
        label = [os.path.join(a.pv, f"{name}.{a.label}.{s}.exr") for s in seeds]
        base = [os.path.join(a.pv, f"{name}.{a.base}.{s}.exr") for s in seeds]
        if scene is None or not all(os.path.exists(p + ".json") for p in label + base):
            continue
        t_label = statistics.mean(cpu_seconds(p) for p in label)
        t_pass = statistics.mean(cpu_seconds(p) for p in base) / a.base_passes
        passes = max(1, round(t_label / t_pass))
        rows = {"base": [], "label": []}
        for seed, judged in zip(seeds, label):
            out = os.path.join(a.pv, f"{name}.{a.base}-eq{passes}.{seed}.exr")
            if not os.path.exists(out):
                subprocess.run(
                    [a.bin, "render", scene, *a.base_flags.split(), "--spp", str(passes),
                     "--seed", str(seed), "--threads", a.threads, "--width", width,
                     "--height", height, "--quiet", "-o", out],
                    check=True,
                )
            rows["base"].append(compare(a.bin, out, reference))
            rows["label"].append(compare(a.bin, judged, reference))
        m = {k: {q: statistics.mean(r[q] for r in v) for q in keys} for k, v in rows.items()}
        ratio = m["label"]["flip"] / m["base"]["flip"]
        ratios.append(ratio)
        print(f"{name}: {a.base} {passes} passes in {a.label}'s {t_label:.1f} CPU s")
        for k, shown in (("base", a.base), ("label", a.label)):
            r = m[k]
            print(f"    {shown}: flip {r['flip']:.4f} mse {r['mse']:.3e} relmse {r['relmse']:.3e} "
                  f"top-1% {100 * r['top1_share']:.0f}%")
        print(f"    {a.label} / {a.base}: flip {ratio:.3f} mse "
              f"{m['label']['mse'] / m['base']['mse']:.3f}", flush=True)
    if ratios:
        print(f"FLIP {a.label} / {a.base} over {len(ratios)} scenes: median "
              f"{statistics.median(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f})")


if __name__ == "__main__":
    main()
