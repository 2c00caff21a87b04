#!/usr/bin/env python3
"""Equal-CPU-time efficiency of `restir` configurations against Mitsuba 3's path tracer.

Development tool: needs `pip install mitsuba numpy` (`llvm_ad_rgb` also needs Debian's
libllvm19); never part of CI or of the project's dependencies.

Scenes are RON or XML. Mitsuba reads an XML scene as it is, or, for a RON scene (and for any
scene with `--convert`, e.g. Lajolla's camelCase files that Mitsuba 3 refuses), the Mitsuba 3
XML that `restir convert` writes of it (into a temporary directory: it rewrites file names for
it). Film size and, with `--max-depth`, the path depth are rewritten in a copy (beside an XML
scene read as it is, so relative asset paths hold; removed after loading); without
`--max-depth` both renderers use the scene's own.

For each scene, each of our configurations (`--config NAME=FLAGS`, flags of `restir render`;
default `path=--integrator path`) and Mitsuba's `path` render at the same size, and each render
is timed by the CPU time it uses, because the machines this runs on are shared and noisy:
ours on one thread, the child process's user+system time minus its load time; Mitsuba on
`--mi-threads` threads of its pool (default 1, `dr.set_thread_count` after loading the scene on
its default pool; 0 keeps its default, one per core), this process's CPU time of all threads around `mi.render` and reading the image
back, after a warm-up render at the same sample count (its kernels compiled). Sample counts
are calibrated (ours from the whole CPU times of 4 and 12 passes; Mitsuba from 4 samples, then once more at the count
that gave) so that each render takes about `--budget` CPU seconds; relMSE is measured by
`restir compare` against a converged reference of our path tracer (`--ref-spp`, all cores,
cached in `--refs`). Renders are interleaved (seed-major: every configuration, then Mitsuba,
for one seed). Prints per scene and renderer the medians over seeds of spp, CPU seconds,
relMSE and efficiency = 1 / (relMSE · seconds), with each configuration's efficiency over
Mitsuba's; then a table of the ratios per scene and their medians.

    python3 scripts/mitsuba_equal_time.py --bin target/release/restir --size 128x96 \\
        --budget 3 --seeds 3 --ref-spp 2048 --config 'path=--integrator path' \\
        --config 'pt=--integrator restir-pt' DIR/*.ron
"""

import argparse
import faulthandler
import hashlib
import importlib.metadata
import json
import os
import re
import resource
import shlex
import shutil
import struct
import statistics
import subprocess
import sys
import tempfile


def child_cpu(cmd):
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(p.pid, 0)
    out, err = p.stdout.read(), p.stderr.read()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"failed: {shlex.join(cmd)}\n{err}")
    return out, usage.ru_utime + usage.ru_stime


def ours(a, scene, flags, spp, seed, out, threads):
    """CPU seconds of one render of ours, minus its load time; and without subtracting it."""
    w, h = a.size.split("x")
    stats = out + ".json"
    depth = [] if a.max_depth is None else ["--max-depth", str(a.max_depth)]
    cmd = [a.bin, "render", scene, *shlex.split(flags), "--spp", str(spp), "--seed", str(seed),
           "--width", w, "--height", h, "--threads", str(threads), "--quiet", *depth,
           "-o", out, "--stats", stats]
    _, cpu = child_cpu(cmd)
    with open(stats) as f:
        load = json.load(f)["load_seconds"]
    return cpu - load, cpu


def relmse(a, test, ref):
    out, _ = child_cpu([a.bin, "compare", test, ref])
    return float(re.search(r"relmse=([0-9.eE+-]+)", out).group(1))


def write_exr(path, rgb):
    """`rgb` (height × width × 3) as an uncompressed float32 scanline EXR. (Mitsuba's own
    `Bitmap.write` hung with a one-thread pool, Mitsuba 3.9.1.)"""
    h, w, _ = rgb.shape

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chans = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in (b"B", b"G", b"R"))
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2)
              + attr("channels", "chlist", chans + b"\0")
              + attr("compression", "compression", b"\0")
              + attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", box)
              + attr("lineOrder", "lineOrder", b"\0")
              + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    line = 12 * w
    first = len(header) + 8 * h
    offsets = struct.pack(f"<{h}Q", *(first + y * (8 + line) for y in range(h)))
    rows = []
    for y in range(h):
        data = b"".join(rgb[y, :, c].astype("<f4").tobytes() for c in (2, 1, 0))
        rows.append(struct.pack("<ii", y, line) + data)
    with open(path, "wb") as f:
        f.write(header + offsets + b"".join(rows))


def self_cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def load_mitsuba(a, mi, scene, w, h):
    """The scene in Mitsuba at this size (and depth): the XML, or the XML `restir convert` writes
    of it, with its film size and the path integrator's max_depth rewritten, in a temporary
    copy beside it (relative paths hold)."""
    if a.convert or not scene.endswith(".xml"):
        # `restir convert` rewrites file names for the directory it writes to.
        tmp = os.path.join(a.work, "scene.xml")
        child_cpu([a.bin, "convert", scene, "-o", tmp])
        text = open(tmp).read()
    else:
        tmp = os.path.join(os.path.dirname(os.path.abspath(scene)),
                           f".mitsuba-et-{os.getpid()}.xml")
        text = open(scene).read()
    values = [("width", w), ("height", h)]
    if a.max_depth is not None:
        values += [("max_depth", a.max_depth), ("maxDepth", a.max_depth)]
    for name, value in values:
        text = re.sub(rf'(name="{name}"\s+value=")[^"]*(")', rf"\g<1>{value}\g<2>", text)
    if a.mi_integrator != "path":
        # Another of Mitsuba's integrators (e.g. `direct`) in place of the scene's, keeping
        # whether emitters seen directly are hidden.
        block = re.search(r'<integrator\b[^>]*?/>|<integrator\b[^>]*>.*?</integrator>',
                          text, re.S)
        if block is None:
            sys.exit(f"{scene}: no <integrator> element to replace with {a.mi_integrator}")
        hide = re.search(r'<boolean name="hide_emitters"[^>]*/>', block.group(0))
        text = (text[:block.start()] + f'<integrator type="{a.mi_integrator}">'
                + (hide.group(0) if hide else "") + "</integrator>" + text[block.end():])
    with open(tmp, "w") as f:
        f.write(text)
    try:
        return mi.load_file(tmp, parallel=False)
    finally:
        os.remove(tmp)


def many_lights_xml(ron):
    """`scenes/many-lights.ron` as Mitsuba 3 XML with each sphere light replaced by a one-sided
    emissive square facing down (-y) at the sphere's centre, half-width the sphere's radius, same
    radiance: 400 small emissive rectangles over diffuse receivers (the many-light scene of the
    equal-time table). Reads the generator's one-shape-per-line RON."""
    num = r"(-?\d+(?:\.\d*)?(?:[eE][+-]?\d+)?)"
    vec = rf"\(\s*{num},\s*{num},\s*{num}\s*\)"
    text = open(ron).read()
    cam = re.search(rf"fov: {num}.*?LookAt\(origin: {vec}, target: {vec}, up: {vec}\)", text, re.S)
    fov, o, t, u = cam.group(1), cam.groups()[1:4], cam.groups()[4:7], cam.groups()[7:10]
    out = ['<scene version="3.0.0">',
           '    <integrator type="path">',
           '        <integer name="max_depth" value="2"/>',
           '        <boolean name="hide_emitters" value="true"/>',
           '    </integrator>',
           '    <sensor type="perspective">',
           f'        <float name="fov" value="{fov}"/>',
           '        <string name="fov_axis" value="x"/>',
           '        <transform name="to_world">',
           f'            <lookat origin="{", ".join(o)}" target="{", ".join(t)}" up="{", ".join(u)}"/>',
           '        </transform>',
           '        <sampler type="independent"><integer name="sample_count" value="16"/></sampler>',
           '        <film type="hdrfilm">',
           '            <integer name="width" value="320"/>',
           '            <integer name="height" value="240"/>',
           '            <rfilter type="box"/>',
           '        </film>',
           '    </sensor>']
    for name, r, g, b in re.findall(rf'\(name: "(\w+)", material: Diffuse\(reflectance: {vec}\)\)', text):
        out.append(f'    <bsdf type="diffuse" id="{name}"><rgb name="reflectance" value="{r}, {g}, {b}"/></bsdf>')
    for line in text.splitlines():
        line = line.strip()
        if not line.startswith("(geometry:"):
            continue
        sph = re.match(rf"\(geometry: Sphere\(center: {vec}, radius: {num}\).*emission: Some\({vec}\)", line)
        if sph:
            x, y, z, rad, *le = sph.groups()
            out += ['    <shape type="rectangle">',
                    '        <transform name="to_world">',
                    f'            <scale value="{rad}"/>',
                    '            <rotate x="1" angle="90"/>',
                    f'            <translate x="{x}" y="{y}" z="{z}"/>',
                    '        </transform>',
                    f'        <emitter type="area"><rgb name="radiance" value="{", ".join(le)}"/></emitter>',
                    '    </shape>']
            continue
        geo = re.match(r"\(geometry: (Rectangle|Cube), to_world: \[(.*?)\], material: Some\(Ref\(\"(\w+)\"\)\)", line)
        if not geo:
            sys.exit(f"unexpected shape line: {line}")
        kind, ops, mat = geo.groups()
        out += [f'    <shape type="{kind.lower()}">', '        <transform name="to_world">']
        depth, start, parts = 0, 0, []
        for i, ch in enumerate(ops + ","):
            depth += (ch == "(") - (ch == ")")
            if ch == "," and depth == 0:
                parts.append(ops[start:i].strip())
                start = i + 1
        for part in filter(None, parts):
            op = part.split("(", 1)[0]
            v = re.findall(r"-?\d+(?:\.\d*)?(?:[eE][+-]?\d+)?", part)
            if op == "Scale":
                out.append(f'            <scale x="{v[0]}" y="{v[1]}" z="{v[2]}"/>')
            elif op == "Rotate":
                out.append(f'            <rotate x="{v[0]}" y="{v[1]}" z="{v[2]}" angle="{v[3]}"/>')
            else:
                out.append(f'            <translate x="{v[0]}" y="{v[1]}" z="{v[2]}"/>')
        out += ['        </transform>', f'        <ref id="{mat}"/>', '    </shape>']
    out.append("</scene>")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene-timeout", type=float, default=2400,
                    help="wall seconds before a scene's process is taken for hung and rerun once")
    ap.add_argument("--child-json", help=argparse.SUPPRESS)
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--bin", default="target/release/restir")
    ap.add_argument("--size", default="128x96")
    ap.add_argument("--max-depth", type=int, default=None,
                    help="both renderers' max depth (default: each scene's own)")
    ap.add_argument("--config", action="append", default=[], metavar="NAME=FLAGS",
                    help="one of our configurations (repeatable; default path=--integrator path)")
    ap.add_argument("--budget", type=float, default=3.0, help="CPU seconds per render")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--refs", default="/tmp/restir-refs")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--mi-threads", type=int, default=1,
                    help="Mitsuba's threads (0: its default, one per core)")
    ap.add_argument("--mi-integrator", default="path",
                    help="Mitsuba's integrator (e.g. direct: replaces the scene's, keeping "
                    "hide_emitters)")
    ap.add_argument("--ref-flags", default="--integrator path",
                    help="restir render flags of the reference (default: the path tracer)")
    ap.add_argument("--convert", action="store_true",
                    help="give Mitsuba XML scenes too as `restir convert` writes them")
    ap.add_argument("--many-lights-xml", metavar="OUT",
                    help="write scenes/many-lights.ron as Mitsuba XML with emissive rectangles "
                    "for its sphere lights (see many_lights_xml) to OUT, and exit")
    a = ap.parse_args()
    if a.many_lights_xml:
        ron = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes",
                           "many-lights.ron")
        with open(a.many_lights_xml, "w") as f:
            f.write(many_lights_xml(ron))
        return
    if not a.scenes:
        ap.error("no scenes given")
    configs = [c.split("=", 1) for c in (a.config or ["path=--integrator path"])]
    if any(len(c) != 2 or not c[0] for c in configs):
        sys.exit("--config: expected NAME=FLAGS")

    if a.child_json is None:
        return parent(a, configs)
    # Where a scene's process hangs, on stderr, before the parent kills it.
    faulthandler.dump_traceback_later(max(a.scene_timeout - 60, 60))

    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant(a.variant)
    w, h = (int(v) for v in a.size.split("x"))
    work = a.work = tempfile.mkdtemp(prefix="mitsuba-et-")
    summary = {}
    for scene in a.scenes:
        ref_flags = "" if a.ref_flags == "--integrator path" else a.ref_flags
        key = hashlib.sha1((open(scene, "rb").read().hex() + a.size + str(a.max_depth)
                            + str(a.ref_spp) + ref_flags).encode()).hexdigest()[:12]
        ref = os.path.join(a.refs, f"{os.path.basename(scene)}-{key}.exr")
        if not os.path.exists(ref):
            ours(a, scene, a.ref_flags, a.ref_spp, 999, ref, 0)

        ms = load_mitsuba(a, mi, scene, w, h)
        # Loaded on Mitsuba's default pool: with one thread, loading a scene with an envmap hung
        # (Mitsuba 3.9.1); rendering on one thread does not.
        if a.mi_threads:
            dr.set_thread_count(a.mi_threads)

        def mitsuba(spp, seed, out):
            t = self_cpu()
            img = mi.render(ms, spp=spp, seed=seed)
            arr = np.array(img)  # forces evaluation
            cpu = self_cpu() - t
            write_exr(out, arr[..., :3])
            return cpu

        # Calibrate CPU seconds per sample (Mitsuba: after compiling for that spp).
        cal = os.path.join(work, "cal.exr")
        spp = {}
        for name, flags in configs:
            # From whole CPU times (the load time is wall-clock: on a loaded machine it is no
            # measure of CPU), more passes if the difference drowns in the noise.
            for more in (12, 36):
                _, o1 = ours(a, scene, flags, 4, 1000, cal, 1)
                _, o2 = ours(a, scene, flags, more, 1000, cal, 1)
                per_pass = (o2 - o1) / (more - 4)
                if per_pass > 0.2 * o2 / more:
                    break
            else:
                sys.exit(f"{scene}: {name}: cannot calibrate the CPU time per pass")
            spp[name] = max(1, round(a.budget / per_pass))
        mitsuba(4, 10_000, cal)
        m1 = mitsuba(4, 10_001, cal)
        n = max(1, round(a.budget / max(m1 / 4, 1e-5)))
        mitsuba(n, 10_002, cal)  # compile for this spp
        # Once more at that count (4 samples carry a larger share of fixed cost).
        m2 = mitsuba(n, 10_003, cal)
        spp["mitsuba"] = max(1, round(n * a.budget / max(m2, 1e-5)))
        if abs(spp["mitsuba"] - n) > 0.1 * n:
            mitsuba(spp["mitsuba"], 10_004, cal)  # compile for the new count
        res = {name: [] for name in spp}
        for seed in range(a.seeds):
            for name, flags in configs:
                out = os.path.join(work, f"{name}.exr")
                cpu, _ = ours(a, scene, flags, spp[name], seed, out, 1)
                res[name].append((cpu, relmse(a, out, ref)))
            out = os.path.join(work, "mi.exr")
            cpu = mitsuba(spp["mitsuba"], seed, out)
            res["mitsuba"].append((cpu, relmse(a, out, ref)))
        eff = {name: statistics.median(1 / (r[0] * r[1]) for r in rows)
               for name, rows in res.items()}
        for name in spp:
            cpu = statistics.median(r[0] for r in res[name])
            err = statistics.median(r[1] for r in res[name])
            ratio = "" if name == "mitsuba" else f"{eff[name] / eff['mitsuba']:.2f}"
            print(f"| {os.path.basename(scene)} | {name} | {spp[name]} | {cpu:.2f} | {err:.4e} | "
                  f"{eff[name]:.3f} | {ratio} |", flush=True)
        summary[scene] = eff
    with open(a.child_json, "w") as f:
        json.dump(summary, f)
    shutil.rmtree(work, ignore_errors=True)


def parent(a, configs):
    """Runs each scene in a process of its own (a fresh Mitsuba per scene; one that hangs is
    killed and rerun), then prints the table of ratios."""
    os.makedirs(a.refs, exist_ok=True)
    depth = "each scene's max depth" if a.max_depth is None else f"max depth {a.max_depth}"
    threads = a.mi_threads or "all"
    version = importlib.metadata.version("mitsuba")
    print(f"# Mitsuba {version} {a.variant} `{a.mi_integrator}` ({threads} thread(s)) vs "
          f"restir (1 thread): "
          f"{', '.join(n for n, _ in configs)}; {a.size}, {depth}, ~{a.budget} CPU s per render "
          f"(process CPU time), {a.seeds} seeds, reference: restir {a.ref_flags} {a.ref_spp} spp")
    print("| scene | renderer | spp | CPU s | relMSE | efficiency | × Mitsuba |")
    print("|---|---|---|---|---|---|---|", flush=True)
    summary = {}
    argv = [x for x in sys.argv[1:] if x not in a.scenes]
    for scene in a.scenes:
        out = tempfile.mktemp(prefix="mitsuba-et-", suffix=".json")
        for attempt in (1, 2):
            child = subprocess.Popen([sys.executable, os.path.abspath(__file__), *argv,
                                      "--child-json", out, scene], start_new_session=True)
            try:
                child.wait(timeout=a.scene_timeout)
                break
            except subprocess.TimeoutExpired:
                os.killpg(child.pid, 9)
                child.wait()
                print(f"# {scene}: no result after {a.scene_timeout:.0f} s "
                      f"(attempt {attempt}; killed)", flush=True)
        if child.returncode != 0 or not os.path.exists(out):
            sys.exit(f"{scene}: failed")
        with open(out) as f:
            summary.update(json.load(f))
        os.remove(out)

    names = [n for n, _ in configs]
    cols = [f"{n} / Mitsuba" for n in names] + [f"{n} / {names[0]}" for n in names[1:]]
    print("\n| scene | " + " | ".join(cols) + " |")
    print("|---|" + "---|" * len(cols))
    ratios = {c: [] for c in cols}
    for scene, eff in summary.items():
        row = [eff[n] / eff["mitsuba"] for n in names] + \
              [eff[n] / eff[names[0]] for n in names[1:]]
        for c, v in zip(cols, row):
            ratios[c].append(v)
        print(f"| {os.path.basename(scene)} | " + " | ".join(f"{v:.2f}" for v in row) + " |")
    print("| **median** | " + " | ".join(f"**{statistics.median(ratios[c]):.2f}**"
                                         for c in cols) + " |")


if __name__ == "__main__":
    main()
