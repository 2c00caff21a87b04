#!/usr/bin/env python3
"""Equal-CPU-time efficiency of `restir`'s path tracer against Mitsuba 3's, on Mitsuba XML scenes.

Development tool: needs `pip install mitsuba numpy` (`llvm_ad_rgb` also needs Debian's
libllvm19); never part of CI or of the project's dependencies.

For each scene both renderers render at the same size and maximum depth, and each render is
timed by the CPU time it uses (ours, on `--threads` threads, 1 by default: the child process's
user+system time minus the CPU time of loading the scene, measured by renders of one 8×8 pass;
Mitsuba, on its own thread pool: this process's CPU time of all threads around `mi.render`, after
a warm-up render that compiles its kernels; with `dr.set_thread_count(1)` Mitsuba 3.9.1 hung
here), because the machines this runs on are shared and noisy. The sample
counts are calibrated so that each render takes about `--budget` CPU seconds; relMSE is measured
by `restir compare` against a converged reference rendered by `restir` (cached in `--refs`).
Renders are interleaved (seed-major). Prints per scene the medians and
efficiency = 1 / (relMSE · seconds), and ours / Mitsuba.

    python3 scripts/mitsuba_equal_time.py --bin target/release/restir --size 256x256 \\
        --max-depth 6 scenes/cornell-box.xml
"""

import argparse
import hashlib
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile


def child_cpu(cmd):
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(p.pid, 0)
    out, err = p.stdout.read(), p.stderr.read()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{err}")
    return out, usage.ru_utime + usage.ru_stime


def ours(a, scene, spp, seed, out, threads, size=None):
    """CPU seconds (user + system) of a whole `restir render`, load included."""
    w, h = (size or a.size).split("x")
    cmd = [a.bin, "render", scene, "--integrator", "path", "--spp", str(spp), "--seed",
           str(seed), "--width", w, "--height", h, "--threads", str(threads), "--quiet",
           "--max-depth", str(a.max_depth), "-o", out]
    _, cpu = child_cpu(cmd)
    return cpu


def load_cpu(a, scene, out):
    """CPU seconds of loading the scene: the median of three renders of one pass at 8×8 pixels
    (the wall-clock `load_seconds` of `--stats` overstates it when the machine is busy)."""
    return statistics.median(ours(a, scene, 1, 1000, out, a.threads, "8x8") for _ in range(3))


def relmse(a, test, ref):
    out, _ = child_cpu([a.bin, "compare", test, ref])
    return float(re.search(r"relmse=([0-9.eE+-]+)", out).group(1))


def self_cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def load_mitsuba(mi, scene, w, h, max_depth):
    """The scene in Mitsuba at this size and depth: the XML with its film size and the path
    integrator's max_depth rewritten, in a temporary copy beside it (relative paths hold)."""
    text = open(scene).read()
    for name, value in (("width", w), ("height", h), ("max_depth", max_depth), ("maxDepth", max_depth)):
        text = re.sub(rf'(name="{name}"\s+value=")[^"]*(")', rf"\g<1>{value}\g<2>", text)
    tmp = os.path.join(os.path.dirname(os.path.abspath(scene)),
                       f".mitsuba-et-{os.getpid()}.xml")
    with open(tmp, "w") as f:
        f.write(text)
    try:
        return mi.load_file(tmp)
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
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--bin", default="target/release/restir")
    ap.add_argument("--size", default="256x256")
    ap.add_argument("--max-depth", type=int, default=6)
    ap.add_argument("--budget", type=float, default=4.0, help="CPU seconds per render")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--refs", default="/tmp/restir-refs")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--threads", type=int, default=1, help="restir's threads")
    ap.add_argument("--mi-threads", type=int, default=0,
                    help="Mitsuba's threads (0: its default; 1 hung here)")
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

    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant(a.variant)
    if a.mi_threads:
        dr.set_thread_count(a.mi_threads)
    w, h = (int(v) for v in a.size.split("x"))
    os.makedirs(a.refs, exist_ok=True)
    work = tempfile.mkdtemp(prefix="mitsuba-et-")
    print(f"# Mitsuba {mi.__version__} {a.variant} ({a.mi_threads or 'all'} threads) vs restir "
          f"({a.threads} thread{'s' if a.threads > 1 else ''}), {a.size}, max depth "
          f"{a.max_depth}, ~{a.budget} CPU s per render (process CPU time), {a.seeds} seeds")
    print("| scene | renderer | spp | CPU s | relMSE | efficiency | ours / Mitsuba |")
    print("|---|---|---|---|---|---|---|")
    for scene in a.scenes:
        key = hashlib.sha1((open(scene, "rb").read().hex() + a.size + str(a.max_depth)
                            + str(a.ref_spp)).encode()).hexdigest()[:12]
        ref = os.path.join(a.refs, f"{os.path.basename(scene)}-{key}.exr")
        if not os.path.exists(ref):
            ours(a, scene, a.ref_spp, 999, ref, 0)
        load = load_cpu(a, scene, os.path.join(work, "cal.exr"))
        print(f"# {os.path.basename(scene)}: restir's load, {load:.3f} CPU s, subtracted",
              flush=True)

        ms = load_mitsuba(mi, scene, w, h, a.max_depth)

        def mitsuba(spp, seed, out):
            t = self_cpu()
            img = mi.render(ms, spp=spp, seed=seed)
            arr = np.array(img)  # forces evaluation
            cpu = self_cpu() - t
            mi.Bitmap(arr[..., :3].astype(np.float32)).write(out)
            return cpu

        # Calibrate CPU seconds per sample (Mitsuba: after compiling for that spp).
        o1 = ours(a, scene, 4, 1000, os.path.join(work, "cal.exr"), a.threads)
        o2 = ours(a, scene, 12, 1000, os.path.join(work, "cal.exr"), a.threads)
        spp_ours = max(1, round(a.budget / max((o2 - o1) / 8, 1e-5)))
        mitsuba(4, 10_000, os.path.join(work, "cal.exr"))
        m1 = mitsuba(4, 10_001, os.path.join(work, "cal.exr"))
        spp_mi = max(1, round(a.budget / max(m1 / 4, 1e-5)))
        mitsuba(spp_mi, 10_002, os.path.join(work, "cal.exr"))  # compile for this spp
        res = {"restir": [], "mitsuba": []}
        for seed in range(a.seeds):
            out = os.path.join(work, "ours.exr")
            cpu = ours(a, scene, spp_ours, seed, out, a.threads) - load
            res["restir"].append((cpu, relmse(a, out, ref)))
            out = os.path.join(work, "mi.exr")
            cpu = mitsuba(spp_mi, seed, out)
            res["mitsuba"].append((cpu, relmse(a, out, ref)))
        eff = {}
        for name, spp in (("restir", spp_ours), ("mitsuba", spp_mi)):
            cpu = statistics.median(r[0] for r in res[name])
            err = statistics.median(r[1] for r in res[name])
            eff[name] = statistics.median(1 / (r[0] * r[1]) for r in res[name])
            ratio = f"{eff['restir'] / eff['mitsuba']:.2f}" if name == "mitsuba" else ""
            print(f"| {os.path.basename(scene)} | {name} | {spp} | {cpu:.2f} | {err:.4e} | "
                  f"{eff[name]:.3f} | {ratio} |", flush=True)


if __name__ == "__main__":
    main()
