#!/usr/bin/env python3
"""Scene load time of one or more restir binaries, first load (table cache off) and second load
(warm cache), interleaved, medians. Development tool, not part of CI.

Usage: scripts/load_times.py [--rounds N] [--cpus 0|0,1] BINARY [BINARY ...] -- SCENE [SCENE ...]

Each run is `restir render SCENE --spp 1 --width 16 --height 16` under `taskset -c CPUS` (the
rough-plastic tables use as many threads as the process may run on, so `--cpus 0` is one thread);
`RESTIR_CACHE_DIR=` (empty: cache off) for a first load, a directory warmed once per binary for a
second. Reported per binary, scene and mode: the median `load_seconds` from `--stats` (wall time
of the load), and the median user+sys CPU of the whole process (`os.wait4`; process start and the
1-spp render included, which the scenes without tables show: about 6 ms).
"""
import argparse, json, os, statistics, subprocess, sys, tempfile


def run(binary, scene, cache, cpus, tmp):
    env = dict(os.environ, RESTIR_CACHE_DIR=cache)
    stats = os.path.join(tmp, "stats.json")
    cmd = ["taskset", "-c", cpus, binary, "render", scene, "--spp", "1", "--width", "16",
           "--height", "16", "--quiet", "--stats", stats, "-o", os.path.join(tmp, "out.exr")]
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL)
    _, status, ru = os.wait4(p.pid, 0)
    if status != 0:
        sys.exit(f"failed: {' '.join(cmd)}")
    with open(stats) as f:
        return json.load(f)["load_seconds"], ru.ru_utime + ru.ru_stime


def main():
    if "--" not in sys.argv:
        sys.exit("usage: load_times.py [--rounds N] [--cpus C] BINARY... -- SCENE...")
    k = sys.argv.index("--")
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--cpus", default="0,1")
    ap.add_argument("binaries", nargs="+")
    a = ap.parse_args(sys.argv[1:k])
    binaries, scenes = [os.path.realpath(b) for b in a.binaries], sys.argv[k + 1:]
    tmp = tempfile.mkdtemp(prefix="restir-load-")
    caches = {b: tempfile.mkdtemp(prefix="cache-", dir=tmp) for b in binaries}
    for b in binaries:  # warm each binary's cache
        for s in scenes:
            run(b, s, caches[b], a.cpus, tmp)
    res = {}
    for _ in range(a.rounds):
        for s in scenes:
            for mode in ("first", "second"):
                for b in binaries:
                    cache = "" if mode == "first" else caches[b]
                    res.setdefault((s, mode, b), []).append(run(b, s, cache, a.cpus, tmp))
    print(f"cpus {a.cpus}, {a.rounds} rounds; median load_seconds (wall) / process CPU seconds")
    print("| scene | mode | " + " | ".join(os.path.basename(b) for b in binaries) + " |")
    print("|---|---|" + "---|" * len(binaries))
    for s in scenes:
        for mode in ("first", "second"):
            cells = []
            for b in binaries:
                v = res[(s, mode, b)]
                cells.append(f"{statistics.median(x[0] for x in v):.4f} / "
                             f"{statistics.median(x[1] for x in v):.4f}")
            print(f"| {os.path.basename(s)} | {mode} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
