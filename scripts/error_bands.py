#!/usr/bin/env python3
"""Where the error lies around emitters seen by the camera: variance per pass by band.

Development tool (needs numpy, scipy and the OpenEXR Python bindings). Renders each
configuration twice (seeds 11 and 12, as `pair_variance.py` does, reusing its renders in `--out`)
and splits the image into bands around the emitters' images: emitter pixels more than three
pixels inside their edge, emitter pixels within three, other pixels within three of an edge,
within six, and the rest. Per band it prints each configuration's variance per pass (the mean of
`(a − b)² / 2 · passes` over the band's pixels, summed over the colour channels) and, against the
first configuration, the ratio of variances per pass and the ratio at equal CPU time (variance
per pass times CPU seconds per pass).

The emitters' image comes from the emission alone on a box filter: a copy of the scene in
`--out` (beside links to what lies beside the scene) with the film's filter replaced by the box
(XML: `<rfilter type="box"/>` as the film's first child; RON: `filter: Box`), rendered by the first configuration's binary with
`--max-depth 1` and 64 passes. An emitter pixel is one whose value is above half the largest
within three pixels (and above 10⁻³).

    python3 scripts/error_bands.py --bin target/release/restir --size 900x540 --out EB \\
        --config 'path=16=--integrator path --max-depth 2' \\
        --config 'di=4=--integrator restir-di --max-depth 2' SCENE.xml
"""

import argparse
import os
import re
import sys

import numpy as np
from scipy import ndimage

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from pair_variance import parse_configs, read_rgb, render  # noqa: E402

SEEDS = (11, 12)


def box_copy(scene, out_dir):
    """A copy of `scene` whose film filters with the box, in `out_dir/box-filter` beside links to
    everything beside the scene (so its relative paths resolve); returns its path. Nothing is
    written beside the scene itself."""
    with open(scene) as f:
        text = f.read()
    ext = os.path.splitext(scene)[1]
    if ext == ".xml":
        text, n = re.subn(r"(<film\b[^>]*>)", r'\1<rfilter type="box"/>', text, count=1)
        if n == 0:
            sys.exit(f"{scene}: no <film> element to give a box filter")
    else:
        text, n = re.subn(r"filter:\s*\w+(\([^)]*\))?", "filter: Box", text, count=1)
        if n == 0:
            sys.exit(f"{scene}: no film filter to replace")
    folder = os.path.join(out_dir, "box-filter")
    os.makedirs(folder, exist_ok=True)
    source = os.path.dirname(os.path.abspath(scene))
    for entry in os.listdir(source):
        link = os.path.join(folder, entry)
        if entry != os.path.basename(scene) and not os.path.lexists(link):
            os.symlink(os.path.join(source, entry), link)
    out = os.path.join(folder, os.path.basename(scene))
    with open(out, "w") as f:
        f.write(text)
    return out


def bands(emission):
    """The named boolean masks of the bands around the emitters' image."""
    e = emission.sum(-1)
    emitter = (e > 0.5 * ndimage.maximum_filter(e, 7)) & (e > 1e-3)
    inside = ndimage.distance_transform_edt(emitter)
    outside = ndimage.distance_transform_edt(~emitter)
    return [
        ("emitters, over 3 px inside", emitter & (inside > 3)),
        ("emitters, within 3 px of the edge", emitter & (inside <= 3)),
        ("others, within 3 px of an edge", ~emitter & (outside <= 3)),
        ("others, 3 to 6 px from an edge", ~emitter & (outside > 3) & (outside <= 6)),
        ("others, beyond 6 px", ~emitter & (outside > 6)),
    ]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="target/release/restir")
    ap.add_argument("--size", default="900x540")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--out", required=True, help="directory for the renders")
    ap.add_argument("--config", action="append", required=True, help="label=passes=flags")
    ap.add_argument("scene")
    a = ap.parse_args()
    configs = parse_configs(a.config)
    os.makedirs(a.out, exist_ok=True)
    name = os.path.splitext(os.path.basename(a.scene))[0]
    first_bin = configs[0][2].split()[0] if configs[0][2].startswith("@") else ""
    mask_flags = f"{first_bin} --integrator path --max-depth 1".strip()
    box = box_copy(a.scene, a.out)
    emission, _ = render(a, box, mask_flags, 64, 1, os.path.join(a.out, f"{name}.emission.exr"))
    masks = bands(emission)
    per_pass, cost = {}, {}
    for label, passes, flags in configs:
        images, seconds = [], []
        for seed in SEEDS:
            img, t = render(a, a.scene, flags, passes, seed,
                            os.path.join(a.out, f"{name}.{label}.{seed}.exr"))
            images.append(img)
            seconds.append(t)
        per_pass[label] = ((images[0] - images[1]) ** 2 / 2).sum(-1) * passes
        cost[label] = sum(seconds) / len(seconds) / passes
    base = configs[0][0]
    print(f"# {name}, {a.size}, {a.threads} thread(s), seeds {SEEDS}; variance per pass, and "
          f"against {base}: per pass and at equal CPU time (> 1: better than {base})")
    for label, _, _ in configs:
        print(f"{label}: {cost[label]:.3f} CPU s per pass")
    for band, m in masks + [("whole image", np.ones_like(masks[0][1]))]:
        cells = []
        for label, _, _ in configs:
            v = float(per_pass[label][m].mean())
            vb = float(per_pass[base][m].mean())
            ratio = vb / v if v > 0 else float("inf")
            cells.append(f"{label} {v:.4g} ({ratio:.2f}x, {ratio * cost[base] / cost[label]:.2f}x)")
        print(f"{band} ({100 * m.mean():.1f} %): " + "; ".join(cells))


if __name__ == "__main__":
    main()
