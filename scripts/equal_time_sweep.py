#!/usr/bin/env python3
"""Equal-CPU-time comparison of integrator configurations over a set of scenes.

Development tool (the machines are shared and noisy: this measures each render's own user CPU
time, from the child's rusage, minus its load time, so other processes on the machine change the
numbers less than wall-clock budgets would). For every scene it renders (or reuses) a path-traced
reference, calibrates each configuration's CPU cost per pass, renders it for about `--budget` CPU
seconds with `--seeds` seeds (interleaved: seed-major, configuration-minor), and prints relMSE,
CPU seconds, efficiency 1/(relMSE·s) and the efficiency relative to the first configuration, per
scene and as the median over scenes. With `--spp N` every configuration renders N passes
instead (equal passes, not equal time) and the rows add each one's error per pass, relMSE × N:
what a pass is worth, apart from what it costs.

    python3 scripts/equal_time_sweep.py --bin target/release/restir --size 160x120 \
        --budget 3 --seeds 3 --refs /tmp/refs \
        --config 'path=--integrator path' --config 'di=--integrator restir-di' \
        scenes/many-lights.ron other.ron ...
"""

import argparse
import hashlib
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile


def run(cmd):
    """Runs `cmd`; returns (stdout, user CPU seconds of the child)."""
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(p.pid, 0)
    out = p.stdout.read()
    err = p.stderr.read()
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        sys.exit(f"failed ({p.returncode}): {shlex.join(cmd)}\n{err}")
    return out, usage.ru_utime


def render(a, scene, flags, spp, seed, out, threads):
    stats = out + ".json"
    w, h = a.size.split("x")
    cmd = [a.bin, "render", scene, *shlex.split(flags), "--spp", str(spp), "--seed", str(seed),
           "--width", w, "--height", h, "--threads", str(threads), "--quiet", "-o", out,
           "--stats", stats]
    _, cpu = run(cmd)
    with open(stats) as f:
        s = json.load(f)
    return cpu, s


def relmse(a, test, ref):
    out, _ = run([a.bin, "compare", test, ref])
    m = re.search(r"relmse=([0-9.eE+-]+)", out)
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--bin", default="target/release/restir")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--budget", type=float, default=3.0, help="CPU seconds per render")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--ref-flags", default="--integrator path")
    ap.add_argument("--refs", default="/tmp/restir-refs")
    ap.add_argument("--config", action="append", required=True, help="NAME=FLAGS")
    ap.add_argument("--spp", type=int, default=None,
                    help="equal passes instead of equal time: every configuration renders this "
                         "many; the table adds each one's error per pass (relMSE × passes)")
    a = ap.parse_args()
    configs = [c.split("=", 1) for c in a.config]
    os.makedirs(a.refs, exist_ok=True)
    work = tempfile.mkdtemp(prefix="sweep-")
    table = {}  # scene -> config -> [efficiency]
    print(f"# {a.size}, ~{a.budget} CPU s per render, {a.threads} thread(s), "
          f"{a.seeds} seeds, reference {a.ref_flags} {a.ref_spp} spp")
    for scene in a.scenes:
        key = hashlib.sha1(
            (open(scene, "rb").read().hex() + a.size + a.ref_flags + str(a.ref_spp)).encode()
        ).hexdigest()[:12]
        ref = os.path.join(a.refs, f"{os.path.basename(scene)}-{key}.exr")
        if not os.path.exists(ref):
            render(a, scene, a.ref_flags, a.ref_spp, 999, ref, 0)
        # Calibrate each configuration's CPU time per pass and its fixed cost (loading the
        # scene, building tables): CPU(n passes) = fixed + n · per pass. The fixed cost is
        # subtracted from every render's CPU time (the wall-clock load time is no measure of CPU
        # on a loaded machine).
        spp, fixed = {}, {}
        for name, flags in configs:
            c1, _ = render(a, scene, flags, 2, 1000, os.path.join(work, "cal.exr"), a.threads)
            c2, _ = render(a, scene, flags, 10, 1000, os.path.join(work, "cal.exr"), a.threads)
            per_pass = max((c2 - c1) / 8, 1e-4)
            fixed[name] = max(c1 - 2 * per_pass, 0.0)
            spp[name] = a.spp or max(1, round(a.budget / per_pass))
        rows = {name: [] for name, _ in configs}
        for seed in range(a.seeds):
            for name, flags in configs:
                out = os.path.join(work, f"{name}.exr")
                cpu, _ = render(a, scene, flags, spp[name], seed, out, a.threads)
                cpu = max(cpu - fixed[name], 0.1 * cpu)
                e = relmse(a, out, ref)
                rows[name].append((e, cpu))
        table[scene] = {}
        base = None
        for name, _ in configs:
            e = statistics.median(r[0] for r in rows[name])
            cpu = statistics.median(r[1] for r in rows[name])
            eff = statistics.median(1.0 / (r[0] * r[1]) for r in rows[name])
            base = base or eff
            table[scene][name] = eff / base
            per_pass = f" | error per pass {e * spp[name]:.4f}" if a.spp else ""
            print(f"{os.path.basename(scene)} | {name} | {spp[name]} spp | relMSE {e:.4e} | "
                  f"{cpu:.2f} s | efficiency {eff:.3f} | ×{eff / base:.2f}{per_pass}", flush=True)
    print("\n| configuration | median × first | min | max |")
    print("|---|---|---|---|")
    for name, _ in configs:
        v = [table[s][name] for s in a.scenes]
        print(f"| {name} | {statistics.median(v):.2f} | {min(v):.2f} | {max(v):.2f} |")


if __name__ == "__main__":
    main()
