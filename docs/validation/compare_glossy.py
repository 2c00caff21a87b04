#!/usr/bin/env python3
"""Cross-checks `restir`'s path tracer against a Mitsuba 3 reference (development only; not CI).

    python3 docs/validation/compare_glossy.py --restir target/release/restir \
        --scene scenes/glossy-still-life.xml --ref-dir REF --work WORK \
        [--spp 16,64,256,1024] [--seeds 2] [--bias-renders 8] [--bias-spp 1024]
        [--images docs/validation/images]

REF is the output of mitsuba_reference.py (ref.exr, half_a.exr, half_b.exr, pass_*.exr).
Prints, as Markdown tables:
  1. relMSE against spp for ours (two seeds per spp), with relMSE·spp and the same after
     subtracting the reference's own noise (relMSE(half_a, half_b) / 4), and the mean ratio per
     channel; Mitsuba's own 512-spp passes against the mean of the other passes, for comparison.
  2. Per-region means: each object's screen region (pixels whose 3×3 neighbourhood sees that
     shape at the pixel centre, found by tracing Mitsuba's camera rays), ours (bias-renders
     independent 1024-spp images) against Mitsuba (its passes), with the ratio and Welch's t.
Writes ours / Mitsuba / difference PNGs to --images.
relMSE is the project's (crates/integrators/src/metrics.rs): mean over pixels and channels of
(x - r)² / (r² + 0.01).
"""
import argparse
import glob
import os
import subprocess

import numpy as np


def load(path):
    import mitsuba as mi

    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def relmse(x, r):
    return float(np.mean((x - r) ** 2 / (r * r + 0.01)))


def render(restir, scene, out, spp, seed):
    if not os.path.exists(out):
        subprocess.run(
            [restir, "render", scene, "-o", out, "--spp", str(spp), "--seed", str(seed), "--quiet"],
            check=True,
        )
    return load(out)


def shape_ids(scene_path, width, height):
    """The id of the shape seen through each pixel centre (Mitsuba's camera)."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    scene = mi.load_file(scene_path, resx=width, resy=height)
    sensor = scene.sensors()[0]
    ids = np.empty((height, width), dtype=object)
    for y in range(height):
        for x in range(width):
            ray, _ = sensor.sample_ray(
                0.0, 0.5, mi.Point2f((x + 0.5) / width, (y + 0.5) / height), mi.Point2f(0.5, 0.5)
            )
            si = scene.ray_intersect(ray)
            ids[y, x] = (si.shape.id() or "back wall + ceiling (merged by Mitsuba)") if si.is_valid() else "none"
    return ids


def regions(ids):
    """Masks of pixels whose 3×3 neighbourhood sees one shape, by shape id."""
    h, w = ids.shape
    out = {}
    for name in sorted(set(ids.ravel())):
        m = ids == name
        core = m.copy()
        core[0, :] = core[-1, :] = core[:, 0] = core[:, -1] = False
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                core[1:-1, 1:-1] &= m[1 + dy : h - 1 + dy, 1 + dx : w - 1 + dx]
        if core.sum() >= 20:
            out[name] = core
    return out


def png(img, path, scale=1.0):
    from PIL import Image

    x = np.clip(img * scale, 0, 1)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    Image.fromarray((x * 255 + 0.5).astype(np.uint8)).resize(
        (img.shape[1] * 2, img.shape[0] * 2), Image.NEAREST
    ).save(path)


def diff_png(a, b, path, full_scale, block=4):
    """Signed relative luminance difference (a - b) / (b + 0.01) averaged over block×block
    pixels (so that a bias shows above the per-pixel noise): red where a is brighter, blue where
    darker, black where equal; full colour at ±full_scale."""
    from PIL import Image

    def lum(i):
        return i @ np.array([0.2126, 0.7152, 0.0722])

    h, w = a.shape[0] // block * block, a.shape[1] // block * block

    def blocks(x):
        return x[:h, :w].reshape(h // block, block, w // block, block).mean(axis=(1, 3))

    la, lb = blocks(lum(a)), blocks(lum(b))
    d = np.clip((la - lb) / (lb + 0.01) / full_scale, -1, 1)
    rgb = np.stack([np.clip(d, 0, 1), np.zeros_like(d), np.clip(-d, 0, 1)], axis=-1)
    Image.fromarray((rgb * 255 + 0.5).astype(np.uint8)).resize(
        (w * 2, h * 2), Image.NEAREST
    ).save(path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--restir", required=True)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--ref-dir", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--spp", default="16,64,256,1024")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--bias-renders", type=int, default=8)
    ap.add_argument("--bias-spp", type=int, default=1024)
    ap.add_argument("--images", default=None)
    args = ap.parse_args()
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    os.makedirs(args.work, exist_ok=True)
    stem = os.path.splitext(os.path.basename(args.scene))[0]

    ref = load(os.path.join(args.ref_dir, "ref.exr"))
    ha, hb = load(os.path.join(args.ref_dir, "half_a.exr")), load(os.path.join(args.ref_dir, "half_b.exr"))
    passes = sorted(glob.glob(os.path.join(args.ref_dir, "pass_*.exr")))
    pimgs = [load(p) for p in passes]
    ref_noise = relmse(ha, hb) / 4
    print(f"reference: {len(passes)} passes, relMSE(half_a, half_b) = {relmse(ha, hb):.3e}, "
          f"reference noise ≈ {ref_noise:.2e}; means {ref.mean(axis=(0, 1))}")

    # 1. relMSE series.
    print("\n| spp | relMSE (seeds) | relMSE·spp | (relMSE − ref. noise)·spp | mean ratio R, G, B |")
    print("|---|---|---|---|---|")
    ours_1024 = None
    for spp in [int(s) for s in args.spp.split(",")]:
        rels, ratios = [], []
        for k in range(args.seeds):
            seed = 1 + k + 10 * spp
            img = render(args.restir, args.scene, os.path.join(args.work, f"ours_{spp}_{seed}.exr"), spp, seed)
            rels.append(relmse(img, ref))
            ratios.append(img.mean(axis=(0, 1)) / ref.mean(axis=(0, 1)))
            if spp == 1024 and ours_1024 is None:
                ours_1024 = img
        r = np.mean(rels)
        rat = np.mean(ratios, axis=0)
        print(f"| {spp} | {' / '.join(f'{x:.3e}' for x in rels)} | {r * spp:.3f} | "
              f"{(r - ref_noise) * spp:.3f} | {rat[0]:.4f}, {rat[1]:.4f}, {rat[2]:.4f} |")
    # Mitsuba's own passes against the mean of the others.
    n = len(pimgs)
    total = np.sum(pimgs, axis=0)
    mrels = []
    for i in range(n):
        others = (total - pimgs[i]) / (n - 1)
        mrels.append(relmse(pimgs[i], others))
    pspp = 512
    others_noise = ref_noise * n / (n - 1)
    mr = np.mean(mrels)
    print(f"| Mitsuba {pspp} (pass vs the other {n - 1}) | {mr:.3e} (mean of {len(mrels)}) | "
          f"{mr * pspp:.3f} | {(mr - others_noise) * pspp:.3f} | |")

    # 2. Regions.
    h, w, _ = ref.shape
    ids = shape_ids(args.scene, w, h)
    masks = regions(ids)
    bspp = args.bias_spp
    suffix = "" if bspp == 1024 else f"_{bspp}"
    ours = [render(args.restir, args.scene, os.path.join(args.work, f"bias_{s}{suffix}.exr"), bspp, 100 + s)
            for s in range(args.bias_renders)]
    print(f"\nRegions: ours {len(ours)} × {bspp} spp (seeds 100–{99 + len(ours)}), Mitsuba {n} × {pspp} spp.")
    print("\n| region | pixels | ours / Mitsuba (R, G, B) | Welch t (R, G, B) |")
    print("|---|---|---|---|")
    masks_all = dict(masks)
    masks_all["whole image"] = np.ones((h, w), dtype=bool)
    for name, m in masks_all.items():
        a = np.array([o[m].mean(axis=0) for o in ours])
        b = np.array([p[m].mean(axis=0) for p in pimgs])
        ma, mb = a.mean(axis=0), b.mean(axis=0)
        se = np.sqrt(a.var(axis=0, ddof=1) / len(a) + b.var(axis=0, ddof=1) / len(b))
        t = (ma - mb) / np.maximum(se, 1e-30)
        ratio = ma / np.maximum(mb, 1e-30)
        print(f"| {name} | {int(m.sum())} | {', '.join(f'{x:.4f}' for x in ratio)} | "
              f"{', '.join(f'{x:+.1f}' for x in t)} |")

    if args.images:
        os.makedirs(args.images, exist_ok=True)
        mean_ours = np.mean(ours, axis=0)
        png(mean_ours, os.path.join(args.images, f"{stem}-ours.png"))
        png(ref, os.path.join(args.images, f"{stem}-mitsuba.png"))
        diff_png(mean_ours, ref, os.path.join(args.images, f"{stem}-diff.png"), 0.03)
        # Region map, for the reader.
        from PIL import Image

        pal = np.array([[230, 25, 75], [60, 180, 75], [255, 225, 25], [0, 130, 200], [245, 130, 48],
                        [145, 30, 180], [70, 240, 240], [240, 50, 230], [210, 245, 60], [250, 190, 212],
                        [0, 128, 128], [220, 190, 255], [170, 110, 40], [128, 0, 0]], dtype=np.uint8)
        rm = np.zeros((h, w, 3), dtype=np.uint8)
        for i, (name, m) in enumerate(masks.items()):
            rm[m] = pal[i % len(pal)]
        Image.fromarray(rm).resize((w * 2, h * 2), Image.NEAREST).save(
            os.path.join(args.images, f"{stem}-regions.png"))
        print("\nregion colours:", {name: pal[i % len(pal)].tolist() for i, name in enumerate(masks)})


if __name__ == "__main__":
    main()
