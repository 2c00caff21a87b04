#!/usr/bin/env python3
"""Cost scaling of the estimators: time per pass against resolution, light count and scene size.

Run from the repository root after `cargo build --release -p restir`:

    python3 scripts/scaling.py [--restir target/release/restir] [--repeats 3] [--out docs/bench]

Every render runs on one thread with `--stats` and the script reads the render's own wall time
(scene loading excluded) from the statistics file. It reports the median over `--repeats`
renders of milliseconds per pass and nanoseconds per pixel-pass, and writes
`<out>/scaling.csv` and `<out>/scaling.md` (the Markdown tables quoted in docs/studies/2026-11-22-cost-scaling.md).
Generated many-light scenes are written to a temporary directory. Development tool; not run in CI.
"""

import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile

PT_TUNED = ["--spatial-rounds", "3", "--neighbors", "4", "--radius", "3", "--candidates", "2",
            "--direct", "path"]
DI_TUNED = ["--light-sampler", "tiles", "--candidates", "8", "--neighbors", "3",
            "--spatial-rounds", "2", "--radius", "3", "--bsdf-candidates", "0"]
CONFIGS = {
    "path": ["--integrator", "path"],
    "restir-di": ["--integrator", "restir-di"],
    "restir-di tuned": ["--integrator", "restir-di"] + DI_TUNED,
    "restir-pt": ["--integrator", "restir-pt"],
    "restir-pt tuned": ["--integrator", "restir-pt"] + PT_TUNED,
}


def render(exe, scene, config, size, passes, tmp, seed):
    stats = os.path.join(tmp, "stats.json")
    cmd = [exe, "render", scene, "--width", str(size), "--height", str(size), "--threads", "1",
           "--quiet", "--seed", str(seed), "--spp", str(passes), "--stats", stats,
           "-o", os.path.join(tmp, "out.exr")] + CONFIGS[config]
    subprocess.run(cmd, check=True)
    with open(stats) as f:
        return json.load(f)


def measure(exe, scene, config, size, passes, repeats, tmp):
    runs = [render(exe, scene, config, size, passes, tmp, seed) for seed in range(repeats)]
    ms = statistics.median(r["seconds"] / r["spp"] * 1e3 for r in runs)
    r = runs[0]
    return {
        "scene": os.path.basename(scene), "config": config, "width": size, "height": size,
        "passes": passes, "triangles": r["triangles"], "spheres": r["spheres"],
        "lights": r["lights"], "ms_per_pass": ms,
        "ns_per_pixel_pass": ms * 1e6 / (size * size),
        "rays_per_pixel_pass": r["rays"] / (r["spp"] * size * size),
        "bytes_per_pixel": r["buffer_bytes_per_pixel"],
    }


def table(rows, key, key_name):
    configs = list(dict.fromkeys(r["config"] for r in rows))
    keys = list(dict.fromkeys(r[key] for r in rows))
    out = [f"| {key_name} | " + " | ".join(f"{c} ms/pass (ns/px)" for c in configs) + " |",
           "|---|" + "---|" * len(configs)]
    for k in keys:
        cells = []
        for c in configs:
            m = [r for r in rows if r[key] == k and r["config"] == c]
            cells.append(f"{m[0]['ms_per_pass']:.1f} ({m[0]['ns_per_pixel_pass']:.0f})" if m else "—")
        out.append(f"| {k} | " + " | ".join(cells) + " |")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--restir", default="target/release/restir")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default="docs/bench")
    ap.add_argument("--corpus", default="../shared/corpus")
    a = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        # Resolution: the indirect room, every estimator.
        res_rows = []
        for size in (64, 128, 256, 512):
            passes = max(2, 32 * 128 * 128 // (size * size))
            for c in ("path", "restir-di", "restir-pt", "restir-pt tuned"):
                res_rows.append(measure(a.restir, "scenes/indirect-room.ron", c, size, passes,
                                        a.repeats, tmp))
                print(res_rows[-1], file=sys.stderr)
        # Light count: generated many-light scenes (same layout seed), 128×128.
        light_rows = []
        for n in (100, 1000, 10000, 100000):
            scene = os.path.join(tmp, f"many-lights-{n}.ron")
            subprocess.run([a.restir, "generate", "many-lights", "--lights", str(n), "-o", scene],
                           check=True, stdout=subprocess.DEVNULL)
            for c in ("path", "restir-di", "restir-di tuned"):
                light_rows.append(measure(a.restir, scene, c, 128, 8, a.repeats, tmp))
                light_rows[-1]["scene"] = f"many-lights ({n})"
                print(light_rows[-1], file=sys.stderr)
        # Scene size: the path tracer (BVH-bound) on scenes from a few dozen triangles to Sponza.
        size_rows = []
        scenes = ["scenes/cornell-box.xml", "scenes/indirect-room.ron",
                  "scenes/glossy-still-life.xml",
                  os.path.join(a.corpus, "restir_test_scene/test.xml"),
                  os.path.join(a.corpus, "lajolla/sponza/sponza.xml")]
        for scene in scenes:
            if not os.path.exists(scene):
                print(f"skipping {scene} (absent)", file=sys.stderr)
                continue
            for c in ("path", "restir-pt tuned"):
                size_rows.append(measure(a.restir, scene, c, 128, 16, a.repeats, tmp))
                print(size_rows[-1], file=sys.stderr)
        rows = res_rows + light_rows + size_rows

    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "scaling.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    for r in size_rows:
        r["scene_size"] = f"{r['scene']} ({r['triangles']} tris, {r['spheres']} spheres)"
    md = ["Resolution (indirect room; ms per pass, in brackets ns per pixel-pass):", "",
          table(res_rows, "width", "width = height"), "",
          "Light count (generated many-light scenes, 128×128):", "",
          table(light_rows, "scene", "scene (lights)"), "",
          "Scene size (128×128):", "",
          table(size_rows, "scene_size", "scene"), ""]
    with open(os.path.join(a.out, "scaling.md"), "w") as f:
        f.write("\n".join(md))
    print("\n".join(md))


if __name__ == "__main__":
    main()
