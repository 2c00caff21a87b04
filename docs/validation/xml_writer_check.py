#!/usr/bin/env python3
"""The Mitsuba 3 XML writer against Mitsuba 3 itself (development cross-check only; not CI).

    python3 docs/validation/xml_writer_check.py --restir target/release/restir \
        --size 128x96 --ours-spp 1024 --mi-passes 8 --mi-spp 512 --work /tmp/xmlcheck \
        SCENE.ron ...

For each scene (RON or XML): `restir convert` writes it as Mitsuba 3 XML (`scene.xml` in the
scene's work directory, file names rewritten for it); our path tracer renders the
scene as given in two halves of `--ours-spp` passes (seeds 1 and 2), Mitsuba 3 renders the XML
in `--mi-passes` independent passes of `--mi-spp` samples (seeds 1000..), both at `--size` and
the scene's own max depth. Each renderer's mean is compared with the other's by the project's
relMSE (mean over pixels and channels of (x - r)^2 / (r^2 + 0.01), as `restir compare`) and by
the ratio of the channel means. The expected relMSE of two unbiased estimates is the sum of
their own noises, each estimated from its halves: relMSE(half A, half B) / 4 (relMSE is
computed against the other estimate, so this is approximate). A relMSE well above that sum, or
a mean ratio off by more than the noise allows, is a mapping bug. Writes `ours.exr`, `mi.exr`
and tone-mapped PNGs (ours, Mitsuba, relative difference of 4x4 blocks at +-5 %) per scene.
"""
import argparse
import os
import subprocess
import sys

import numpy as np


def relmse(x, r):
    return float(np.mean((x - r) ** 2 / (r ** 2 + 0.01)))


def png(path, img):
    import mitsuba as mi
    rgb = np.clip(img, 0, None)
    srgb = np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * np.power(rgb, 1 / 2.4) - 0.055)
    mi.Bitmap(np.clip(srgb * 255 + 0.5, 0, 255).astype(np.uint8)).write(path)


def diff_png(path, a, b, scale=0.05, block=4):
    la = a @ np.array([0.2126, 0.7152, 0.0722])
    lb = b @ np.array([0.2126, 0.7152, 0.0722])
    h, w = la.shape
    h4, w4 = h // block * block, w // block * block
    ba = la[:h4, :w4].reshape(h4 // block, block, w4 // block, block).mean(axis=(1, 3))
    bb = lb[:h4, :w4].reshape(h4 // block, block, w4 // block, block).mean(axis=(1, 3))
    d = np.clip((ba - bb) / (bb + 0.01) / scale, -1, 1)
    img = np.ones(d.shape + (3,))
    img[..., 1] = 1 - np.abs(d)
    img[..., 0] = np.where(d < 0, 1 - np.abs(d), 1)
    img[..., 2] = np.where(d > 0, 1 - np.abs(d), 1)
    img = np.repeat(np.repeat(img, block, axis=0), block, axis=1)
    import mitsuba as mi
    mi.Bitmap((img * 255).astype(np.uint8)).write(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--restir", default="target/release/restir")
    ap.add_argument("--size", default="128x96")
    ap.add_argument("--ours-spp", type=int, default=1024, help="passes per half (two halves)")
    ap.add_argument("--mi-passes", type=int, default=8)
    ap.add_argument("--mi-spp", type=int, default=512)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--work", default="/tmp/xmlcheck")
    a = ap.parse_args()

    import mitsuba as mi
    mi.set_variant(a.variant)
    w, h = a.size.split("x")
    print("| scene | ours / Mitsuba mean (R, G, B) | relMSE(ours, Mitsuba) | ours noise | "
          "Mitsuba noise | relMSE / (sum of noises) |")
    print("|---|---|---|---|---|---|")
    for scene in a.scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        out = os.path.join(a.work, name)
        os.makedirs(out, exist_ok=True)
        xml = os.path.join(out, "scene.xml")  # file names inside are rewritten for `out`
        subprocess.run([a.restir, "convert", scene, "-o", xml], check=True,
                       stdout=subprocess.DEVNULL)
        ms = mi.load_file(xml, resx=int(w), resy=int(h))
        halves = []
        for seed in (1, 2):
            path = os.path.join(out, f"ours-half{seed}.exr")
            if not os.path.exists(path):
                subprocess.run([a.restir, "render", scene, "--integrator", "path", "--spp",
                                str(a.ours_spp), "--seed", str(seed), "--width", w, "--height",
                                h, "--quiet", "-o", path], check=True)
            halves.append(np.array(mi.Bitmap(path), dtype=np.float64)[..., :3])
        passes = []
        for i in range(a.mi_passes):
            path = os.path.join(out, f"mi-pass{1000 + i}.exr")
            if not os.path.exists(path):
                img = np.array(mi.render(ms, spp=a.mi_spp, seed=1000 + i))[..., :3]
                mi.Bitmap(img.astype(np.float32)).write(path)
            passes.append(np.array(mi.Bitmap(path), dtype=np.float64)[..., :3])
        ours = np.mean(halves, axis=0)
        mit = np.mean(passes, axis=0)
        mi_a, mi_b = np.mean(passes[0::2], axis=0), np.mean(passes[1::2], axis=0)
        noise_ours = relmse(halves[0], halves[1]) / 4
        noise_mi = relmse(mi_a, mi_b) / 4
        e = relmse(ours, mit)
        ratio = ours.reshape(-1, 3).mean(axis=0) / mit.reshape(-1, 3).mean(axis=0)
        mi.Bitmap(ours.astype(np.float32)).write(os.path.join(out, "ours.exr"))
        mi.Bitmap(mit.astype(np.float32)).write(os.path.join(out, "mi.exr"))
        png(os.path.join(out, "ours.png"), ours)
        png(os.path.join(out, "mi.png"), mit)
        diff_png(os.path.join(out, "diff.png"), ours, mit)
        print(f"| {name} | {ratio[0]:.4f}, {ratio[1]:.4f}, {ratio[2]:.4f} | {e:.3e} | "
              f"{noise_ours:.3e} | {noise_mi:.3e} | {e / (noise_ours + noise_mi):.2f} |",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
