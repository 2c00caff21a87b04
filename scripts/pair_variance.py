#!/usr/bin/env python3
"""Equal-CPU-time efficiency of unbiased configurations from pairs of renders, without a reference.

Development tool (needs numpy and the OpenEXR Python bindings). For an unbiased estimator the
mean squared error of a render is its variance, and two renders with independent seeds `a`, `b`
estimate it per pixel without a reference: `E[(a − b)²] / 2`. A reference of finite passes adds
its own variance to every configuration's relMSE and pulls their ratios towards 1 (at 640×360 a
1024-pass path-traced reference of the DI training hall, member 10, adds about a third to a
16-pass ReSTIR DI render's error), so this measures more sharply for the same CPU time.

Per scene, every configuration renders `--passes` passes (its own count) with each of two seeds,
interleaved seed-major; its relative variance is the mean over pixels and channels of
`(a − b)² / 2 / (m² + 0.01)`, `m` the mean of all renders of the scene (the same denominator for
every configuration, as `restir compare`'s relMSE uses the reference; a bright outlier of a
render raises `m` where it falls and so weighs less, and two configurations that render alike
from the same seeds, one estimator from two builds, say, count their shared outliers twice in
`m` and favour themselves against a third: compare such a third in MSE, which has no
denominator); its time is the child's
user + system CPU time minus its load time (`--stats`' `load_seconds`); its efficiency is
1 / (relative variance × CPU seconds), which does not depend on the pass count when a pass's
cost does not. Prints, per scene and as the median over scenes, each configuration's efficiency
relative to the first, also in plain squared error (MSE: `(a − b)² / 2` without the denominator,
which weighs bright pixels as a viewer does), and the share of its squared error in the 1 % of
pixels where it is largest (how concentrated the noise is; from two renders, so it reads high,
the more so the heavier the tail of a configuration's per-pixel errors).

With four seeds (`--seeds 11,12,13,14`) each configuration renders two independent pairs: the
variances are their mean, and the hardest pixels' figures are also given held out: the top 1 %
and the worst 1 % chosen from one pair's 3×3 means and read from the other pair, both ways,
averaged. Chosen and read from the same pair, the hardest 1 % is partly pixels whose estimate
is high by chance, which inflates the share and lowers the worst-1 % efficiency of whichever
configuration chose them; held out, they estimate the share of the expected squared error. The
figures not marked held out come from the first pair, as a run with two seeds gives them.

A configuration is `label=passes=flags`; flags that start with `@PATH` render with the binary
at PATH instead of `--bin` (two builds in one run). Renders are kept in `--out` and reused when
their stats file exists, so an interrupted run resumes.

    python3 scripts/pair_variance.py --bin target/release/restir --size 640x360 --threads 1 \\
        --out /tmp/pv --config 'path=16=--integrator path' \\
        --config 'di=4=--integrator restir-di' FAMILY/di-test-*.ron

With `--mitsuba INTEGRATOR --mitsuba-spp N` (needs `pip install mitsuba`), Mitsuba 3 renders
each scene too, as `restir convert` writes it, with its integrator replaced by INTEGRATOR (e.g.
`direct`), in `--mitsuba-variant` (default `llvm_ad_rgb`; with Debian's `libllvm19`, point
`DRJIT_LIBLLVM_PATH` at `libLLVM-19.so`) on `--threads` threads, after one
discarded render at the same sample count (the JIT compiles for it); its time is this process's
CPU time around `mi.render` (scene loading and compiling excluded), and its row is named
`mitsuba`. The conversion and loading are `scripts/mitsuba_equal_time.py`'s.

Only for unbiased configurations: a bias is invisible to its variances (use `restir compare`
against a converged reference, or the statistical tests, for that). With `--bias` it prints, per
scene and seed, each configuration's image sum against the first's, relative and in standard
errors of that difference (from the spread of 16×16-pixel block sums): a quick screen for a
difference between two configurations that both claim to be unbiased, not a proof of either.
"""

import argparse
import json
import os
import shlex
import statistics
import subprocess
import sys

import numpy as np
import OpenEXR
import Imath

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def read_rgb(path):
    f = OpenEXR.InputFile(path)
    dw = f.header()["dataWindow"]
    w, h = dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1
    pt = Imath.PixelType(Imath.PixelType.FLOAT)
    chans = [np.frombuffer(f.channel(c, pt), dtype=np.float32).reshape(h, w) for c in "RGB"]
    return np.stack(chans, -1).astype(np.float64)


def parse_configs(strings):
    """`label=passes=flags` strings as (label, passes, flags); exits on a malformed one."""
    configs = []
    for c in strings:
        parts = c.split("=", 2)
        if len(parts) != 3 or not parts[1].isdigit():
            sys.exit(f"--config {c!r}: expected label=passes=flags")
        configs.append((parts[0], int(parts[1]), parts[2]))
    return configs


def render(a, scene, flags, passes, seed, out):
    """Renders once unless `out`'s stats exist; returns (image, CPU seconds without loading)."""
    stats = out + ".json"
    if not os.path.exists(stats):
        w, h = a.size.split("x")
        words = shlex.split(flags)
        # A configuration may name its own binary first (`@PATH`), to compare builds in one run.
        binary = words.pop(0)[1:] if words and words[0].startswith("@") else a.bin
        cmd = [binary, "render", scene, *words, "--spp", str(passes), "--seed",
               str(seed), "--width", w, "--height", h, "--threads", str(a.threads), "--quiet",
               "-o", out, "--stats", stats + ".tmp"]
        p = subprocess.Popen(cmd, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(p.pid, 0)
        err = p.stderr.read().decode()
        if os.waitstatus_to_exitcode(status) != 0:
            sys.exit(f"failed: {shlex.join(cmd)}\n{err}")
        with open(stats + ".tmp") as f:
            s = json.load(f)
        s["cpu_seconds"] = usage.ru_utime + usage.ru_stime - s["load_seconds"]
        with open(stats + ".tmp", "w") as f:
            json.dump(s, f)
        os.replace(stats + ".tmp", stats)
    with open(stats) as f:
        s = json.load(f)
    return read_rgb(out), s["cpu_seconds"]


def mitsuba_renders(a, scene, name, seeds):
    """One render of `scene` by Mitsuba 3 per seed (module documentation): images and CPU
    seconds."""
    import tempfile
    import drjit as dr
    import mitsuba as mi
    import mitsuba_equal_time as met

    mi.set_variant(a.mitsuba_variant)
    images, cpu = [], []
    outs = [os.path.join(a.out, f"{name}.mitsuba.{seed}.exr") for seed in seeds]
    stats = os.path.join(a.out, f"{name}.mitsuba.json")
    if os.path.exists(stats):
        with open(stats) as f:
            cpu = json.load(f)
        if len(cpu) == len(seeds):
            return [read_rgb(o) for o in outs], cpu
        cpu = []
    w, h = a.size.split("x")
    a.work = tempfile.mkdtemp(prefix="pair-variance-")
    a.convert, a.max_depth, a.mi_integrator = True, None, a.mitsuba
    # Loaded on a pool of every core: loading a scene with an environment map on a one-thread
    # pool hangs (Mitsuba 3.9.1); rendering on one thread does not.
    dr.set_thread_count(os.cpu_count())
    ms = met.load_mitsuba(a, mi, scene, w, h)
    dr.set_thread_count(a.threads)
    mi.render(ms, spp=a.mitsuba_spp, seed=10_000).numpy()
    for seed, out in zip(seeds, outs):
        t = met.self_cpu()
        arr = np.array(mi.render(ms, spp=a.mitsuba_spp, seed=seed))
        cpu.append(met.self_cpu() - t)
        met.write_exr(out, arr[..., :3])
        images.append(read_rgb(out))
    with open(stats, "w") as f:
        json.dump(cpu, f)
    return images, cpu


def mean_difference(x, y, block=16):
    """The sum over the image of `x − y` relative to `y`'s, and in standard errors estimated from
    the spread of its `block × block`-pixel sums (reuse correlates neighbouring pixels, so
    per-pixel errors would understate it; blocks wider than the reuse radius do not)."""
    d = (x - y).sum(-1)
    h, w = d.shape[0] // block * block, d.shape[1] // block * block
    sums = d[:h, :w].reshape(h // block, block, w // block, block).sum((1, 3)).ravel()
    total = float(sums.sum())
    se = float(np.sqrt(sums.var() * sums.size))
    return total / max(float(y.sum()), 1e-30), total / se if se > 0 else 0.0


def box3(a):
    """The mean of each pixel's 3×3 neighbourhood (edges repeated): per-pixel squared errors from
    two renders are one-degree chi-square noise; a neighbourhood's mean is steadier."""
    p = np.pad(a, 1, mode="edge")
    h, w = a.shape
    return sum(p[i:i + h, j:j + w] for i in range(3) for j in range(3)) / 9.0


def worst_share_efficiency(sq, t, sq_base, t_base, held=None):
    """Equal-time squared-error efficiency against the first configuration within this
    configuration's own worst 1 % of pixels (by the 3×3 means of the squared error times CPU
    time): > 1 where even its hardest pixels are better than the first configuration's there.

    `sq` and `sq_base` are per-pixel squared errors (summed over channels). With `held`, a
    second independent pair `(sq2, sq2_base)`, the pixels are chosen from `sq` and the
    efficiency read from the held-out pair, so the choice does not favour pixels whose
    estimate is high by chance (see `held_out`)."""
    e = box3(sq) * t
    k = max(1, e.size // 100)
    worst = np.argsort(e.ravel())[-k:]
    num, den = (held[1], held[0]) if held else (sq_base, sq)
    e_base, e = box3(num) * t_base, box3(den) * t
    return float(e_base.ravel()[worst].sum() / max(e.ravel()[worst].sum(), 1e-30))


def top_share(sq, held=None):
    """The share of the squared error in the 1 % of pixels where it is largest; with `held`,
    the share of the held-out pair's squared error in the 1 % of pixels where `sq`'s 3×3 means
    are largest."""
    k = max(1, sq.size // 100)
    if held is None:
        per_pixel = np.sort(sq.ravel())[::-1]
        return float(per_pixel[:k].sum() / max(per_pixel.sum(), 1e-30))
    top = np.argsort(box3(sq).ravel())[-k:]
    return float(held.ravel()[top].sum() / max(held.sum(), 1e-30))


def held_out(f, first, second):
    """`f(first, held=second)` and `f(second, held=first)` averaged: a statistic of the hardest
    pixels chosen from one pair of renders and read from the other. From the pair that chose
    them, the hardest 1 % is partly the pixels whose one-degree chi-square estimate is high by
    chance, which inflates the share of the configuration with fewer, heavier-tailed samples
    per pixel; held out, it is the share of the expected squared error."""
    return (f(first, second) + f(second, first)) / 2


def pairs(imgs):
    """Per pixel and channel, each pair of renders' squared error `(a − b)² / 2`."""
    return [(imgs[i] - imgs[i + 1]) ** 2 / 2 for i in range(0, len(imgs), 2)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="target/release/restir")
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--seeds", default="11,12",
                    help="two seeds, or four for held-out figures of the hardest pixels, "
                         "comma-separated")
    ap.add_argument("--out", required=True, help="directory for the renders")
    ap.add_argument("--config", action="append", required=True, help="label=passes=flags")
    ap.add_argument("--mitsuba", help="also render with this Mitsuba 3 integrator (e.g. direct)")
    ap.add_argument("--mitsuba-spp", type=int, default=16)
    ap.add_argument("--mitsuba-variant", default="llvm_ad_rgb")
    ap.add_argument("--bias", action="store_true",
                    help="also print each configuration's image sum against the first's, per seed")
    ap.add_argument("scenes", nargs="+")
    a = ap.parse_args()
    seeds = [int(s) for s in a.seeds.split(",")]
    if len(seeds) not in (2, 4) or len(set(seeds)) != len(seeds):
        sys.exit("--seeds takes two or four different seeds")
    configs = parse_configs(a.config)
    os.makedirs(a.out, exist_ok=True)
    base = configs[0][0]
    ratios = {label: [] for label, _, _ in configs}
    ratios_mse = {label: [] for label, _, _ in configs}
    print(f"# {a.size}, {a.threads} thread(s), seeds {seeds}; efficiency relative to {base}")
    for scene in a.scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        images, cpu = {}, {}
        for seed in seeds:
            for label, passes, flags in configs:
                out = os.path.join(a.out, f"{name}.{label}.{seed}.exr")
                img, t = render(a, scene, flags, passes, seed, out)
                images.setdefault(label, []).append(img)
                cpu.setdefault(label, []).append(t)
        rows = list(configs)
        if a.mitsuba:
            images["mitsuba"], cpu["mitsuba"] = mitsuba_renders(a, scene, name, seeds)
            rows.append(("mitsuba", a.mitsuba_spp, a.mitsuba))
        # Mitsuba's images are not in the mean: the denominator stays ours, whatever its film.
        m = np.mean([img for label, imgs in images.items() if label != "mitsuba" for img in imgs],
                    axis=0)
        denom = m * m + 1e-2
        eff, eff_mse = {}, {}
        cells = []
        sq_base, t_base = pairs(images[base]), statistics.mean(cpu[base])
        for label, passes, _ in rows:
            sqs = pairs(images[label])
            sq = np.mean(sqs, axis=0)
            rel_var = float(np.mean(sq / denom))
            mse = float(np.mean(sq))
            pixel = [q.sum(-1) for q in sqs]
            top = f"top-1% {100 * top_share(pixel[0]):.0f}%"
            if len(pixel) == 2:
                top += f" (held out {100 * held_out(top_share, *pixel):.0f}%)"
            t = statistics.mean(cpu[label])
            eff[label] = 1.0 / (rel_var * t) if rel_var > 0 and t > 0 else float("inf")
            eff_mse[label] = 1.0 / (mse * t) if mse > 0 and t > 0 else float("inf")
            worst = ""
            if label != base and label != "mitsuba" and sq.shape == sq_base[0].shape:
                base_pixel = [q.sum(-1) for q in sq_base]
                w = worst_share_efficiency(pixel[0], t, base_pixel[0], t_base)
                worst = f" (MSE in its worst 1% {w:.2f}x"
                if len(pixel) == 2:
                    w = held_out(
                        lambda a, held: worst_share_efficiency(a[0], t, a[1], t_base, held),
                        (pixel[0], base_pixel[0]), (pixel[1], base_pixel[1]))
                    worst += f", held out {w:.2f}x"
                worst += ")"
            cells.append(f"{label}: relvar {rel_var:.3g} mse {mse:.3g} {top}"
                         f"{worst} cpu {t:.2f}s ({t / passes:.3f}/pass)")
        for label in eff:
            ratios.setdefault(label, []).append(eff[label] / eff[base])
            ratios_mse.setdefault(label, []).append(eff_mse[label] / eff_mse[base])
        print(name)
        for (label, _, _), cell in zip(rows, cells):
            # Three significant digits: a ratio far below 1 (Mitsuba against ReSTIR, say) keeps
            # its precision for ratios taken from these lines.
            print(f"    {cell}  eff {eff[label] / eff[base]:.3g}x "
                  f"(MSE {eff_mse[label] / eff_mse[base]:.3g}x)", flush=True)
        if a.bias:
            for label, _, _ in configs[1:]:
                parts = [mean_difference(images[label][k], images[base][k])
                         for k in range(len(seeds))]
                print(f"    {label} - {base}, image sum: " + ", ".join(
                    f"seed {seed} {100 * rel:+.2f} % ({z:+.1f} s.e.)"
                    for seed, (rel, z) in zip(seeds, parts)))
    print(f"median over {len(a.scenes)} scenes (range), efficiency relative to {base}, "
          "in relative variance and in MSE:")
    for label, r in ratios.items():
        q = ratios_mse[label]
        print(f"    {label}: {statistics.median(r):.2f}x ({min(r):.2f}-{max(r):.2f}); "
              f"MSE {statistics.median(q):.2f}x ({min(q):.2f}-{max(q):.2f})")
    if a.mitsuba:
        print(f"median (range), efficiency relative to Mitsuba 3 {a.mitsuba} "
              f"({a.mitsuba_variant}, {a.threads} thread(s)):")
        for label, r in ratios.items():
            rel = [x / y for x, y in zip(r, ratios["mitsuba"])]
            rel_mse = [x / y for x, y in zip(ratios_mse[label], ratios_mse["mitsuba"])]
            print(f"    {label}: {statistics.median(rel):.2f}x ({min(rel):.2f}-{max(rel):.2f}); "
                  f"MSE {statistics.median(rel_mse):.2f}x "
                  f"({min(rel_mse):.2f}-{max(rel_mse):.2f})")


if __name__ == "__main__":
    main()
