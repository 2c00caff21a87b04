#!/usr/bin/env python3
"""The CPU cost of a ReSTIR DI pass over a path-traced pass,
against a target of at most 1.5×.

Development tool. For each scene, at 160x120 and 640x480, both estimators render n1 and n2
passes; a pass costs (CPU(n2) - CPU(n1)) / (n2 - n1) of the child's user+system time, so loading
and set-up cancel (the wall-clock load time is no measure of CPU on a loaded machine). Rounds
are interleaved; medians. Also prints how ReSTIR DI's wall time splits into its stages
(`--stats` stage_seconds).

    python3 scripts/pass_cost.py --bin target/release/restir --rounds 3 --threads 1 SCENES...
"""
import argparse, os, subprocess, statistics, json, tempfile
ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("scenes", nargs="+")
ap.add_argument("--bin", default="target/release/restir")
ap.add_argument("--rounds", type=int, default=3)
ap.add_argument("--threads", default="1")
ap.add_argument("--di-flags", default="", help="extra restir-di flags")
a = ap.parse_args()
b, R, T = a.bin, a.rounds, a.threads
work = tempfile.mkdtemp(prefix="pass-cost-")
def run(scene, flags):
    out = os.path.join(work, "pass.exr")
    p = subprocess.Popen([b, "render", scene, *flags.split(), "--threads", T, "--quiet", "-o", out, "--stats", out + ".json"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, st, ru = os.wait4(p.pid, 0); assert os.waitstatus_to_exitcode(st) == 0, p.stderr.read()
    return ru.ru_utime + ru.ru_stime, json.load(open(out + ".json"))
for scene in a.scenes:
    for w, h, n1, n2 in [(160, 120, 4, 36), (640, 480, 1, 5)]:
        per = {"path": [], "di": []}
        stages = {}
        for r in range(R):
            for name, flags in (("path", "--integrator path"), ("di", "--integrator restir-di " + a.di_flags)):
                c1, _ = run(scene, f"{flags} --spp {n1} --width {w} --height {h}")
                c2, st = run(scene, f"{flags} --spp {n2} --width {w} --height {h}")
                per[name].append((c2 - c1) / (n2 - n1))
                for d in st.get("stage_seconds", []):
                    stages.setdefault(d["stage"], []).append(d["seconds"] / n2)
        mp, md = statistics.median(per["path"]), statistics.median(per["di"])
        tot = sum(statistics.median(v) for v in stages.values())
        st = " ".join(f"{k} {statistics.median(v)/tot*100:.0f}%" for k, v in stages.items())
        print(f"{os.path.basename(scene)[:14]} {w}x{h} threads {T}: path {mp*1000:.1f} ms/pass, di {md*1000:.1f} ms/pass, di/path {md/mp:.2f} | di wall split: {st}")
