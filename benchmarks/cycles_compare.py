"""hemilight against Blender's Cycles on a stand-in level: error against time for both,
and Cycles' time at the same error as hemilight's.

  /usr/bin/python3 benchmarks/cycles_compare.py [--quick] [--level arena] [--triangles T]
      [--lightmap-size S] [--size 1024] [--bounces 1] [--samples 16,64,256,1024]
      [--hemilight 32:0.2,64:0.1,...] [--reference-n 128] [--reference-samples 2048]
      [--reference-seeds 2] [--threads 2] [--no-sun] [--work DIR] [--csv OUT.csv] [--plot-only] [--force]

Steps (each bake's outputs are kept in --work, default build-bench/cycles/LEVEL_SIZE, and reused on
a later run unless --force; every bake runs alone, one after another):
1. build-bench/examples/hemilight_make_level LEVEL LEVEL.glb [--triangles T] [--lightmap-size S]: the
   level as glTF binary, degenerate triangles included (hemilight_bake takes them; Cycles' results are
   bit for bit the same without them); its printed --sun and --sky are used by both bakers (--no-sun:
   the sky alone; the files get the suffix _sky).
2. hemilight: build-bench/examples/hemilight_bake LEVEL.glb --size SIZE --resolution N --error A
   --bounces B --threads 2 --sun ... --sky ... (A = "none": --no-cache), for every N:A of
   --hemilight (default 32:0.2, 64:0.2, 64:0.1, 64:none); wall time of the command
   (import, bake, EXR and PNG writing) and the bake's own "total".
3. Cycles: blender -b -P benchmarks/cycles_bake.py -- LEVEL.glb OUT.exr --size SIZE --samples K ...
   (DIFFUSE, direct + indirect, colour off, x pi: irradiance; see cycles_bake.py) for every K of
   --samples; wall time of the command (Blender's start, the glTF import, the bake, the EXR) and the
   bake operator's own time.
4. References: hemilight --no-cache at N = --reference-n (default 128: a hemicube per texel), and
   Cycles at --reference-samples (default 2048) with --reference-seeds independent seeds (default 2),
   averaged; their split-half difference estimates the Cycles reference's own noise. The two are
   checked against each other (median ratio, quartiles and RMS).
5. Where Cycles evaluates the texels: cycles_bake.py --position (16 samples, two seeds) against the
   texel centres computed here from the glb's UVs. Cycles' bake spreads each texel's samples over its
   footprint (anti-aliasing), and on long thin UV triangles (the levels' strips) far beyond it.
6. Errors: luminance (Rec. 709), relative RMS = sqrt(sum dY^2 / sum Y_ref^2), over three texel sets of
   the hemilight reference's mask: valid (sampled, not inside geometry); interior (valid and fully
   covered: hemilight samples the texel at its centre there); comparable (interior, its 8 neighbours
   interior too, so away from chart borders and from the geometry inside solids that invalid texels
   mark, and Cycles' mean sample position within a quarter texel of the centre in both seeds).
   Against the Cycles reference also with its noise taken out (sqrt(e^2 - noise^2)). Texels where a
   reference is not finite are left out of every set and counted (Cycles writes NaN at a few
   texels); a bake's own non-finite texels are left out of its error and counted
   (nonfinite_valid_texels).
   Rows: both EXRs have the same row order for a glb (glTF's v = 0 is row 0 in hemilight and Blender's
   top scanline); every run checks it (the flipped comparison must be far worse).
Writes --csv (default docs/bench/cycles_LEVEL_SIZE.csv), its chart (.png, same name: error against
time, interior texels against the hemilight reference, comparable texels against it, and each
renderer against its own reference) and NAME_check.txt (the references' agreement, where Cycles
samples), and prints Cycles' time at each hemilight bake's error and hemilight's time at each Cycles
bake's error in four views (log-log interpolation along each renderer's error-time front; "beyond"
where a renderer never reached it).
--quick: the arena at 10,000 triangles packed for 256², baked at 256², samples 16, 64, 256,
hemilight 32:0.2, 64:0.2, 64:none, references N = 128 and 1024 samples x 2 (a few minutes).
The default run takes about 30 minutes on two cores (the references 25 of them).
Needs Debian's blender (3.4.1; `apt-get install blender`, benchmarks/README.md), numpy and matplotlib
for /usr/bin/python3, and build-bench with the examples (benchmarks/run.sh configures it so).
"""
import argparse
import csv
import math
import os
import re
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BUILD = os.path.join(ROOT, "build-bench")
MAKE_LEVEL = os.path.join(BUILD, "examples", "hemilight_make_level")
BAKE = os.path.join(BUILD, "examples", "hemilight_bake")
EXR_NPY = os.path.join(BUILD, "benchmarks", "exr_npy")


def load1():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def run(cmd, log):
    """Runs cmd (a list), appends its output to `log`, returns (wall seconds, stdout + stderr)."""
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    with open(log, "a") as f:
        f.write("$ " + " ".join(cmd) + "\n" + p.stdout + p.stderr + f"[exit {p.returncode}, {wall:.2f} s]\n")
    if p.returncode != 0:
        sys.exit(f"cycles_compare: failed ({p.returncode}): {' '.join(cmd)}\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    return wall, p.stdout + p.stderr


def load_exr(path, work):
    import numpy as np

    npy = os.path.join(work, "tmp.npy")
    subprocess.run([EXR_NPY, path, npy], check=True)
    return np.load(npy)


def lum(a):
    return 0.2126 * a[..., 0] + 0.7152 * a[..., 1] + 0.0722 * a[..., 2]


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--level", default="arena")
    p.add_argument("--triangles", type=int, default=0)
    p.add_argument("--lightmap-size", type=int, default=0)
    p.add_argument("--size", type=int, default=0)
    p.add_argument("--bounces", type=int, default=1)
    p.add_argument("--samples", default="")
    p.add_argument("--hemilight", default="")
    p.add_argument("--reference-n", type=int, default=128)
    p.add_argument("--reference-samples", type=int, default=0)
    p.add_argument("--reference-seeds", type=int, default=2)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--no-sun", action="store_true")
    p.add_argument("--work", default="")
    p.add_argument("--csv", default="")
    p.add_argument("--plot-only", action="store_true")
    p.add_argument("--force", action="store_true")
    a = p.parse_args()
    if a.quick:  # defaults for what is not given
        a.triangles, a.lightmap_size, a.size = a.triangles or 10000, a.lightmap_size or 256, a.size or 256
        a.samples, a.hemilight = a.samples or "16,64,256", a.hemilight or "32:0.2,64:0.2,64:none"
        a.reference_samples = a.reference_samples or 1024
    a.size = a.size or 1024
    a.samples = a.samples or "16,64,256,1024"
    a.hemilight = a.hemilight or "32:0.2,64:0.2,64:0.1,64:none"
    a.reference_samples = a.reference_samples or 2048
    tag = (f"{a.level}{'_' + str(a.triangles) if a.triangles else ''}_{a.size}{'_b' + str(a.bounces) if a.bounces != 1 else ''}"
           f"{'_sky' if a.no_sun else ''}")
    a.work = a.work or os.path.join(BUILD, "cycles", tag)
    a.csv = a.csv or os.path.join(ROOT, "docs", "bench", f"cycles_{tag}.csv")
    a.tag = tag
    return a


class Runner:
    def __init__(self, a):
        self.a = a
        os.makedirs(a.work, exist_ok=True)
        self.log = os.path.join(a.work, "log.txt")
        self.times = os.path.join(a.work, "times.csv")  # label -> wall, bake, load before, after

    def recorded(self):
        out = {}
        if os.path.exists(self.times):
            for r in csv.DictReader(open(self.times)):
                out[r["label"]] = r
        return out

    def record(self, label, wall, bake, before, after, extra=""):
        new = not os.path.exists(self.times)
        with open(self.times, "a") as f:
            if new:
                f.write("label,wall_seconds,bake_seconds,load1_before,load1_after,extra\n")
            f.write(f"{label},{wall:.3f},{bake:.3f},{before:.2f},{after:.2f},{extra}\n")

    def level(self):
        glb = os.path.join(self.a.work, f"{self.a.level}.glb")
        info = os.path.join(self.a.work, "level.txt")
        if self.a.force or not os.path.exists(info):
            cmd = [MAKE_LEVEL, self.a.level, glb]
            if self.a.triangles:
                cmd += ["--triangles", str(self.a.triangles)]
            if self.a.lightmap_size:
                cmd += ["--lightmap-size", str(self.a.lightmap_size)]
            _, out = run(cmd, self.log)
            with open(info, "w") as f:
                f.write(out)
        out = open(info).read()
        m = re.search(r"--sun (\S+)", out)
        s = re.search(r"--sky (\S+)", out)
        self.sun, self.sky = (m.group(1) if m and not self.a.no_sun else ""), (s.group(1) if s else "1,1,1")
        self.glb = glb
        self.level_line = out.splitlines()[0]
        return glb

    def hemilight(self, n, a_text, label):
        out_dir = os.path.join(self.a.work, label)
        exr = os.path.join(out_dir, f"{self.a.level}_irradiance.exr")
        if not self.a.force and label in self.recorded() and os.path.exists(exr):
            return exr
        cmd = [BAKE, self.glb, "--size", str(self.a.size), "--resolution", str(n), "--bounces", str(self.a.bounces),
               "--threads", str(self.a.threads), "--sky", self.sky, "--quiet", "--out", out_dir]
        cmd += ["--no-cache"] if a_text == "none" else ["--error", a_text]
        if self.sun:
            cmd += ["--sun", self.sun]
        before = load1()
        print(f"  hemilight {label} ...", flush=True)
        wall, out = run(cmd, self.log)
        total = re.search(r"total ([0-9.]+) s", out)
        hc = re.findall(r"([0-9]+) hemicubes", out)
        self.record(label, wall, float(total.group(1)) if total else wall, before, load1(),
                    str(sum(int(x) for x in hc)))
        return exr

    def cycles(self, samples, seed, label, position=False):
        exr = os.path.join(self.a.work, f"{label}.exr")
        if not self.a.force and label in self.recorded() and os.path.exists(exr):
            return exr
        cmd = ["blender", "-b", "-noaudio", "-P", os.path.join(HERE, "cycles_bake.py"), "--", self.glb, exr,
               "--size", str(self.a.size), "--samples", str(samples), "--sky", self.sky, "--bounces", str(self.a.bounces),
               "--threads", str(self.a.threads), "--seed", str(seed)]
        if position:
            cmd += ["--position"]
        if self.sun:
            cmd += ["--sun", self.sun]
        before = load1()
        print(f"  cycles {label} ...", flush=True)
        wall, out = run(cmd, self.log)
        m = re.search(r"cycles_bake: import ([0-9.]+) s, bake ([0-9.]+) s", out)
        self.record(label, wall, float(m.group(2)) if m else wall, before, load1(), m.group(1) if m else "")
        return exr


def front_time_at(points, err):
    """Time at which a renderer's error-time front reaches `err`: points (time, error); the front is
    the lowest error reached by each time; log-log interpolation between its points. None if the
    front never gets down to err."""
    pts = sorted(points)
    front, best = [], math.inf
    for t, e in pts:
        if e < best:
            front.append((t, e))
            best = e
    if not front or err < front[-1][1]:
        return None
    if err >= front[0][1]:
        return front[0][0]
    for (t0, e0), (t1, e1) in zip(front, front[1:]):
        if e1 <= err <= e0:
            if e0 == e1:
                return t0
            f = math.log(e0 / err) / math.log(e0 / e1)
            return math.exp(math.log(t0) + f * math.log(t1 / t0))
    return None


def texel_centres(glb, size):
    """World positions (glTF axes) of the texel centres of a size x size map through TEXCOORD_1 of
    the glb's triangles (NaN where no triangle of nonzero UV area contains the centre), computed
    here from the file (barycentrics in double)."""
    import json
    import struct

    import numpy as np

    b = open(glb, "rb").read()
    n = struct.unpack("<I", b[12:16])[0]
    j = json.loads(b[20:20 + n])
    bin0 = 20 + n + 8

    def acc(i):
        a = j["accessors"][i]
        bv = j["bufferViews"][a["bufferView"]]
        off = bin0 + bv.get("byteOffset", 0) + a.get("byteOffset", 0)
        k = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
        dt = {5126: np.float32, 5125: np.uint32, 5123: np.uint16}[a["componentType"]]
        return np.frombuffer(b, dtype=dt, count=a["count"] * k, offset=off).reshape(a["count"], k)

    out = np.full((size, size, 3), np.nan)
    for mesh in j["meshes"]:
        for pr in mesh["primitives"]:
            P = acc(pr["attributes"]["POSITION"]).astype(np.float64)
            U = acc(pr["attributes"]["TEXCOORD_1"]).astype(np.float64) * size
            I = acc(pr["indices"]).reshape(-1, 3)
            for t in range(len(I)):
                a, bb, c = U[I[t]]
                area = (bb[0] - a[0]) * (c[1] - a[1]) - (bb[1] - a[1]) * (c[0] - a[0])
                if abs(area) < 1e-12:
                    continue
                x0, x1 = max(0, int(math.floor(min(a[0], bb[0], c[0])))), min(size - 1, int(math.ceil(max(a[0], bb[0], c[0]))))
                y0, y1 = max(0, int(math.floor(min(a[1], bb[1], c[1])))), min(size - 1, int(math.ceil(max(a[1], bb[1], c[1]))))
                xs, ys = np.meshgrid(np.arange(x0, x1 + 1) + 0.5, np.arange(y0, y1 + 1) + 0.5)
                w0 = ((bb[0] - xs) * (c[1] - ys) - (bb[1] - ys) * (c[0] - xs)) / area
                w1 = ((c[0] - xs) * (a[1] - ys) - (c[1] - ys) * (a[0] - xs)) / area
                w2 = 1.0 - w0 - w1
                ins = (w0 >= 0) & (w1 >= 0) & (w2 >= 0)
                if not ins.any():
                    continue
                p3 = w0[ins, None] * P[I[t][0]] + w1[ins, None] * P[I[t][1]] + w2[ins, None] * P[I[t][2]]
                out[(ys[ins] - 0.5).astype(int), (xs[ins] - 0.5).astype(int)] = p3
    return out


def main():
    import numpy as np

    a = parse_args()
    r = Runner(a)
    hl_specs = [(int(x.split(":")[0]), x.split(":")[1]) for x in a.hemilight.split(",")]
    samples = [int(x) for x in a.samples.split(",")]
    if not a.plot_only:
        print(f"cycles_compare {a.tag}: work {a.work}; load average {load1():.2f}", flush=True)
        r.level()
        print("  " + r.level_line, flush=True)
        r.hemilight(a.reference_n, "none", f"hl_ref_n{a.reference_n}")
        for n, at in hl_specs:
            r.hemilight(n, at, f"hl_n{n}_a{at}")
        for k in samples:
            r.cycles(k, 0, f"cy_s{k}")
        for seed in range(a.reference_seeds):
            r.cycles(a.reference_samples, seed + 1, f"cy_ref_s{a.reference_samples}_seed{seed + 1}")
        for seed in (1, 2):
            r.cycles(16, seed, f"cy_pos_seed{seed}", position=True)
    else:
        r.level()
    times = r.recorded()

    # texel sets (hemilight reference's mask): valid; interior = valid and fully covered;
    # interior8 = interior with its 8 neighbours interior too (a texel away from chart borders and
    # from the invalid texels that mark geometry inside solids)
    ref_dir = os.path.join(a.work, f"hl_ref_n{a.reference_n}")
    mask = load_exr(os.path.join(ref_dir, f"{a.level}_mask.exr"), a.work)
    valid = mask[..., 1] > 0.5
    interior = valid & (mask[..., 0] >= 0.999)
    pad = np.pad(interior, 1)
    interior8 = np.ones_like(interior)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            interior8 &= pad[1 + dy:pad.shape[0] - 1 + dy, 1 + dx:pad.shape[1] - 1 + dx]
    # where Cycles evaluates each texel: its mean sample position (two seeds) against the texel centre
    m = re.search(r"in (\d+) x \d+ texels \(padding \d+, ([0-9.]+) texels/m", r.level_line)
    texel = (int(m.group(1)) / a.size) / float(m.group(2)) if m else float("nan")  # metres per texel at SIZE
    centres = texel_centres(r.glb, a.size)
    pos = [load_exr(os.path.join(a.work, f"cy_pos_seed{s}.exr"), a.work) for s in (1, 2)]
    pos = [np.stack([p[..., 0], p[..., 2], -p[..., 1]], -1) for p in pos]  # Blender's axes to glTF's
    off = [np.linalg.norm(p - centres, axis=-1) / texel for p in pos]
    seeds_apart = np.linalg.norm(pos[0] - pos[1], axis=-1) / texel
    on_centre = np.isfinite(off[0])
    placed = on_centre & (off[0] < 0.25) & (off[1] < 0.25) & (seeds_apart < 0.25)
    comparable = interior8 & placed
    sel_i = interior & on_centre
    positions = (f"Cycles' mean sample position per texel (16 samples, 2 seeds) against the texel centre, interior texels "
                 f"(texel {texel:.3f} m): more than half a texel away {float(np.mean(off[0][sel_i] > 0.5)):.1%}, more than "
                 f"2 texels {float(np.mean(off[0][sel_i] > 2)):.1%}, max {float(np.nanmax(off[0][sel_i])):.0f} texels; the two "
                 f"seeds' means more than 0.25 texel apart {float(np.mean(seeds_apart[sel_i] > 0.25)):.1%}; comparable "
                 f"texels (interior, 8 interior neighbours, Cycles within 0.25 texel in both seeds): {int(comparable.sum())} "
                 f"of {int(interior.sum())} interior")
    print(positions)

    H = lum(load_exr(os.path.join(ref_dir, f"{a.level}_irradiance.exr"), a.work))
    refs = [lum(load_exr(os.path.join(a.work, f"cy_ref_s{a.reference_samples}_seed{s + 1}.exr"), a.work))
            for s in range(a.reference_seeds)]
    C = sum(refs) / len(refs)
    # Texels where a reference is not finite (Cycles writes NaN at a few texels) are left out of
    # every set, and counted; a bake's own non-finite texels are left out of its error and counted.
    finite_refs = np.isfinite(H) & np.isfinite(C)
    nonfinite_refs = (f"texels left out (a reference not finite there): {int((valid & ~np.isfinite(H)).sum())} "
                      f"valid texels of the hemilight reference, {int((valid & ~np.isfinite(C)).sum())} of the Cycles "
                      f"reference")
    print(nonfinite_refs)

    def rel_rms(x, ref, sel):
        sel = sel & np.isfinite(x) & np.isfinite(ref)
        d = x[sel] - ref[sel]
        return float(math.sqrt((d * d).sum() / (ref[sel] ** 2).sum()))

    valid, interior, comparable = valid & finite_refs, interior & finite_refs, comparable & finite_refs
    sets = {"valid": valid, "interior": interior, "comparable": comparable}
    # the Cycles reference's own noise: half the difference of two seeds, over sqrt(seeds / 2) more
    noise = {}
    if len(refs) >= 2:
        for nm, sel in sets.items():
            half = 0.5 * (refs[0] - refs[1])
            noise[nm] = math.sqrt(float((half[sel] ** 2).sum() / (C[sel] ** 2).sum())) * math.sqrt(2.0 / len(refs))
    checks = []
    for nm in ("interior", "comparable"):
        sel = sets[nm]
        lit = sel & (H > 0.01 * float(H[valid].mean()))
        ratio = C[lit] / H[lit]
        checks.append(f"{nm} texels ({int(sel.sum())}; lit above 1% of the mean {int(lit.sum())}): median ratio "
                      f"{float(np.median(ratio)):.4f}, quartiles {float(np.percentile(ratio, 25)):.4f}-"
                      f"{float(np.percentile(ratio, 75)):.4f}, relative RMS between them {rel_rms(C, H, sel):.2%}, "
                      f"the Cycles reference's own noise {noise.get(nm, float('nan')):.2%}")
    check = (f"Cycles reference ({a.reference_samples} samples x {len(refs)} seeds) against hemilight reference (N = "
             f"{a.reference_n}, a hemicube per texel): " + "; ".join(checks))
    print(check)

    rows = []
    cy_first = None
    for label, t in times.items():
        if label.startswith("cy_pos"):
            continue
        if label.startswith("hl_"):
            exr = os.path.join(a.work, label, f"{a.level}_irradiance.exr")
            renderer = "hemilight_reference" if label.startswith("hl_ref") else "hemilight"
            mm = re.match(r"hl_(?:ref_)?n(\d+)(?:_a(\S+))?", label)
            n, at, k = int(mm.group(1)), (mm.group(2) or "none"), ""
        else:
            exr = os.path.join(a.work, f"{label}.exr")
            renderer = "cycles_reference" if label.startswith("cy_ref") else "cycles"
            k = int(re.match(r"cy_(?:ref_)?s(\d+)", label).group(1))
            n, at = "", ""
        if not os.path.exists(exr):
            continue
        Y = lum(load_exr(exr, a.work))
        if renderer == "cycles" and cy_first is None:
            cy_first = (label, Y)
        row = dict(renderer=renderer, label=label, n=n, a=at, samples=k, wall_seconds=float(t["wall_seconds"]),
                   bake_seconds=float(t["bake_seconds"]), hemicubes=t["extra"] if renderer.startswith("hemilight") else "",
                   nonfinite_valid_texels=int((valid & ~np.isfinite(Y)).sum()))
        for nm, sel in sets.items():
            row[f"rms_{nm}"] = rel_rms(Y, H, sel)
        for nm, sel in sets.items():
            e = rel_rms(Y, C, sel)
            row[f"rms_{nm}_vs_cycles"] = e
            row[f"rms_{nm}_vs_cycles_noise_out"] = math.sqrt(max(0.0, e ** 2 - noise.get(nm, 0.0) ** 2))
        row.update(load1_before=float(t["load1_before"]), load1_after=float(t["load1_after"]), size=a.size,
                   bounces=a.bounces, level=a.level, threads=a.threads)
        rows.append(row)
    if cy_first is not None:
        flipped = rel_rms(cy_first[1][::-1], H, interior)
        straight = rel_rms(cy_first[1], H, interior)
        print(f"row order check ({cy_first[0]}): interior relative RMS {straight:.2%} as read, {flipped:.2%} flipped")
        if flipped < straight:
            print("WARNING: the flipped rows agree better: the row convention is not what cycles_bake.py says")
    order = {"hemilight": 0, "hemilight_reference": 1, "cycles": 2, "cycles_reference": 3}
    rows.sort(key=lambda x: (order[x["renderer"]], x["wall_seconds"]))
    with open(a.csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(a.csv[:-4] + "_check.txt", "w") as f:
        f.write(r.level_line + "\n" + positions + "\n" + nonfinite_refs + "\n" + check + "\n")
    print(f"wrote {a.csv}")

    print(f"\n{r.level_line}\n{a.size}², {a.bounces} bounce(s), {a.threads} threads; relative RMS of luminance")
    print("| renderer | setting | wall s (bake s) | interior vs hemilight ref | comparable vs hemilight ref | "
          "interior vs Cycles ref (noise out) | comparable vs Cycles ref (noise out) | valid vs hemilight ref |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for x in rows:
        setting = (f"N = {x['n']}, " + ("no cache" if x["a"] == "none" else f"a = {x['a']}")) if x["renderer"].startswith("hemilight") \
            else f"{x['samples']} samples"
        print(f"| {x['renderer']} | {setting} | {x['wall_seconds']:.1f} ({x['bake_seconds']:.1f}) | {x['rms_interior']:.2%} | "
              f"{x['rms_comparable']:.2%} | {x['rms_interior_vs_cycles_noise_out']:.2%} | "
              f"{x['rms_comparable_vs_cycles_noise_out']:.2%} | {x['rms_valid']:.2%} |")
    views = (("rms_interior", "rms_interior", "interior texels, both against the hemilight reference"),
             ("rms_comparable", "rms_comparable", "comparable texels, both against the hemilight reference"),
             ("rms_comparable", "rms_comparable_vs_cycles_noise_out",
              "comparable texels, each against its own reference (Cycles': noise taken out)"),
             ("rms_interior", "rms_interior_vs_cycles_noise_out",
              "interior texels, each against its own reference (Cycles': noise taken out)"))
    for hl_key, cy_key, what in views:
        hl = [(x["wall_seconds"], x[hl_key], x) for x in rows if x["renderer"] == "hemilight"]
        cy = [(x["wall_seconds"], x[cy_key], x) for x in rows if x["renderer"] == "cycles"]
        print(f"\n{what} (wall time of each command):")
        for t, e, x in hl:
            tc = front_time_at([(p[0], p[1]) for p in cy], e)
            print(f"  hemilight N = {x['n']}, a = {x['a']}: {e:.2%} in {t:.1f} s; Cycles at that error: "
                  + (f"{tc:.1f} s ({tc / t:.1f}x)" if tc else "beyond its best measured"))
        for t, e, x in cy:
            th = front_time_at([(p[0], p[1]) for p in hl], e)
            print(f"  Cycles {x['samples']} samples: {e:.2%} in {t:.1f} s; hemilight at that error: "
                  + (f"{th:.1f} s ({th / t:.2f}x)" if th else "beyond its best measured"))
    plot(a, rows, r.level_line, views)


def plot(a, rows, level_line, views):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(19, 6.5))
    for ax, (hl_key, cy_key, title) in zip(axes, views[:3]):
        for renderer, key, style, color in (("hemilight", hl_key, "o", "tab:blue"), ("cycles", cy_key, "s-", "tab:red")):
            pts = sorted((x["wall_seconds"], x[key], x) for x in rows if x["renderer"] == renderer)
            if not pts:
                continue
            ax.plot([p[0] for p in pts], [max(p[1], 1e-5) for p in pts], style, color=color,
                    label="hemilight (N, cache threshold a)" if renderer == "hemilight" else "Cycles (samples per texel)")
            for t, e, x in pts:
                lab = (f"N{x['n']} " + ("no cache" if x["a"] == "none" else f"a={x['a']}")) if renderer == "hemilight" \
                    else f"{x['samples']} spp"
                ax.annotate(lab, (t, max(e, 1e-5)), textcoords="offset points", xytext=(4, 3), fontsize=7, color=color)
        for renderer, key, color in (("hemilight_reference", hl_key, "tab:blue"), ("cycles_reference", cy_key, "tab:red")):
            for x in rows:
                if x["renderer"] == renderer and x[key] > 1e-6:
                    ax.plot([x["wall_seconds"]], [x[key]], "D", color=color, mfc="none")
                    ax.annotate("reference run", (x["wall_seconds"], x[key]), textcoords="offset points", xytext=(4, -9),
                                fontsize=6, color=color)
        ax.axhline(0.01, color="k", ls=":", lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(f"wall time of the command, {a.threads} threads (s)")
        ax.set_ylabel("relative RMS error of luminance")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"{level_line.split(',')[0]}, {a.size}², {a.bounces} bounce(s), its sun and sky: hemilight "
                 f"against Cycles (Blender 3.4.1, CPU, {a.threads} threads). References: hemilight N = {a.reference_n} "
                 f"with a hemicube per texel; Cycles {a.reference_samples} samples x {a.reference_seeds} seeds", fontsize=9)
    fig.tight_layout()
    out = a.csv[:-4] + ".png"
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
