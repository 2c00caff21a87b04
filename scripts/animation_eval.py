#!/usr/bin/env python3
"""Per-frame evidence for estimators on an animated sequence, at equal CPU time per frame.

Development tool (needs numpy and OpenEXR: `pip install numpy OpenEXR`). It renders (or reuses)
a path-traced reference of every frame, calibrates each configuration's CPU time per pass on the
sequence, renders the whole sequence with each configuration at about `--budget` CPU seconds
per frame for `--seeds` seeds (interleaved: seed-major, configuration-minor; a frame's CPU time
is the whole run's user CPU time over the frames, loading and per-frame scene builds included,
which every configuration pays alike), and prints per
configuration: the mean over frames of the per-frame relMSE, CPU seconds per frame, efficiency
1/(relMSE·s) relative to the first configuration, and flicker: the mean over consecutive frames
of the relative squared change of the error, ((I_f - R_f) - (I_f-1 - R_f-1))^2 /
(max(R_f, R_f-1)^2 + 0.01),
i.e. the variance of frame-to-frame differences beyond the reference's own (independent noise per
frame gives about twice the relMSE; errors that persist across frames give less). `--per-frame`
also prints each frame's relMSE, and `--keep DIR` keeps the renders.

    python3 scripts/animation_eval.py --bin target/release/restir --size 128x96 --frames 0..23 \
        --budget 0.5 --seeds 2 --refs /tmp/anim-refs \
        --config 'spatial=--integrator restir-di' \
        --config 'spatiotemporal=--integrator restir-di --temporal' \
        scenes/many-lights-flythrough.ron
"""

import argparse
import hashlib
import os
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile

import numpy as np
import OpenEXR


def run(cmd):
    """Runs `cmd`; returns the child's user CPU seconds."""
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(p.pid, 0)
    err = p.stderr.read()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"failed: {shlex.join(cmd)}\n{err}")
    return usage.ru_utime


def read(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.asarray(ch["RGB"].pixels, dtype=np.float64)
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)


def frame_files(out, first, last):
    stem, ext = os.path.splitext(out)
    return [f"{stem}_{n:04d}{ext}" for n in range(first, last + 1)]


def render(a, scene, flags, spp, seed, out, threads):
    w, h = a.size.split("x")
    fps = ["--fps", a.fps] if a.fps else []
    cmd = [a.bin, "render", scene, "--frames", a.frames, *fps, *shlex.split(flags), "--spp", str(spp),
           "--seed", str(seed), "--width", w, "--height", h, "--threads", str(threads),
           "--quiet", "-o", out]
    return run(cmd)


def relmse(img, ref):
    return float(np.mean((img - ref) ** 2 / (ref * ref + 0.01)))


def flicker(imgs, refs):
    errs = [i - r for i, r in zip(imgs, refs)]
    v = [np.mean((errs[f] - errs[f - 1]) ** 2 / (np.maximum(refs[f], refs[f - 1]) ** 2 + 0.01))
         for f in range(1, len(errs))]
    return float(np.mean(v)) if v else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--bin", default="target/release/restir")
    ap.add_argument("--frames", required=True, help="A..B")
    ap.add_argument("--size", default="128x96")
    ap.add_argument("--budget", type=float, default=0.5, help="CPU seconds per frame")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--ref-flags", default="--integrator path")
    ap.add_argument("--refs", default="/tmp/restir-anim-refs")
    ap.add_argument("--config", action="append", required=True, help="NAME=FLAGS")
    ap.add_argument("--per-frame", action="store_true")
    ap.add_argument("--keep", help="keep the renders in this directory")
    ap.add_argument("--fps", help="passed to every render (a huge rate makes a still sequence)")
    a = ap.parse_args()
    first, last = (int(x) for x in a.frames.split(".."))
    configs = [c.split("=", 1) for c in a.config]
    key = hashlib.sha1((open(a.scene, "rb").read().hex() + a.size + a.frames + a.ref_flags
                        + str(a.ref_spp) + str(a.fps)).encode()).hexdigest()[:12]
    refdir = os.path.join(a.refs, f"{os.path.basename(a.scene)}-{key}")
    ref_out = os.path.join(refdir, "ref.exr")
    if not all(os.path.exists(p) for p in frame_files(ref_out, first, last)):
        os.makedirs(refdir, exist_ok=True)
        render(a, a.scene, a.ref_flags, a.ref_spp, 999, ref_out, 0)
    refs = [read(p) for p in frame_files(ref_out, first, last)]
    frames = last - first + 1
    work = a.keep or tempfile.mkdtemp(prefix="anim-")
    os.makedirs(work, exist_ok=True)
    print(f"# {a.scene}, frames {a.frames}, {a.size}, ~{a.budget} CPU s per frame, "
          f"{a.threads} thread(s), {a.seeds} seeds, reference {a.ref_flags} {a.ref_spp} spp")
    spp = {}
    for name, flags in configs:
        cal = os.path.join(work, "cal.exr")
        c1 = render(a, a.scene, flags, 1, 1000, cal, a.threads)
        c3 = render(a, a.scene, flags, 3, 1000, cal, a.threads)
        per_pass = max((c3 - c1) / (2 * frames), 1e-5)
        spp[name] = max(1, round(a.budget / per_pass))
    rows = {name: [] for name, _ in configs}
    for seed in range(a.seeds):
        for name, flags in configs:
            out = os.path.join(work, f"{name}-{seed}.exr")
            cpu = render(a, a.scene, flags, spp[name], seed, out, a.threads)
            cpu = cpu / frames
            imgs = [read(p) for p in frame_files(out, first, last)]
            per = [relmse(i, r) for i, r in zip(imgs, refs)]
            rows[name].append((per, cpu, flicker(imgs, refs)))
    base_eff = base_flicker = None
    print("\n| configuration | spp per frame | mean relMSE | CPU s per frame | efficiency × first "
          "| flicker | flicker × first |")
    print("|---|---|---|---|---|---|---|")
    for name, _ in configs:
        e = statistics.median(statistics.mean(r[0]) for r in rows[name])
        cpu = statistics.median(r[1] for r in rows[name])
        fl = statistics.median(r[2] for r in rows[name])
        eff = statistics.median(1.0 / (statistics.mean(r[0]) * r[1]) for r in rows[name])
        base_eff = base_eff or eff
        base_flicker = base_flicker or fl
        print(f"| {name} | {spp[name]} | {e:.4e} | {cpu:.3f} | {eff / base_eff:.2f} | {fl:.4e} "
              f"| {fl / base_flicker:.2f} |", flush=True)
    if a.per_frame:
        print("\nper-frame relMSE (median over seeds)")
        print("frame " + " ".join(f"{n:>12}" for n, _ in configs))
        for f in range(frames):
            vals = [statistics.median(r[0][f] for r in rows[n]) for n, _ in configs]
            print(f"{first + f:5d} " + " ".join(f"{v:12.4e}" for v in vals))
    if not a.keep:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
