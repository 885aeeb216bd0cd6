#!/usr/bin/env python3
"""docs/performance.md from sf_bench JSON: the seeds' performance tables in their own shapes
(seed 000 Tables 6.1, 7.1, 7.3, 8.1; seed 002 Table 2), each cell our frame rate beside the
seed's, and the stages of the default frame against their floor or peer (issue 31's table).

Usage:
  scripts/performance_tables.py --cpu CPU.json [MORE.json ...] [--gpu GPU.json ...] [--out docs/performance.md]
                                [--gpu-doc docs/gpu.md]
CPU.json is `make performance`'s run on PoCL (build/performance.json); GPU.json the same
benchmarks on a GPU (scripts/gpu/remote.sh's bench.json with SF_BENCH_FILTER=$(PERF_FILTER)).
With --gpu, the GPU's column is filled and --gpu-doc's figures section (between the markers
below) is rewritten with the GPU's tables; without it the GPU column says "not measured".
Every figure is the median of the run's repetitions; the bench's own figures, never edited."""
import argparse
import json
import re
import sys

GPU_BEGIN = "<!-- performance_tables.py: begin -->"
GPU_END = "<!-- performance_tables.py: end -->"

# The seeds' figures as printed (seed 000: Annen's thesis; seed 002: coherent shadow maps).
SEED_000_HW = "NVIDIA GeForce 8800 GTX, dual-core AMD Opteron (OpenGL / DirectX 10), frames with rasterisation and shading"
SEED_61 = {  # (C, row) -> fps per S = 256, 512, 1024, 2048; 1024x768
    (1, "PCF"): [76, 74, 71, 69],
    (1, "M = 4"): [64, 62, 60, 50], (1, "M = 8"): [55, 53, 49, 38], (1, "M = 16"): [47, 45, 39, 26],
    (3, "M = 4"): [63, 61, 57, 43], (3, "M = 8"): [53, 50, 44, 30], (3, "M = 16"): [42, 39, 32, 19],
    (7, "M = 4"): [62, 60, 53, 36], (7, "M = 8"): [52, 49, 41, 24], (7, "M = 16"): [41, 38, 28, 14],
}
SEED_71 = {  # (C, S) -> fps of ESM-T, ESM-Z, VSM, CSM
    (1, 512): [145, 132, 152, 83], (1, 1024): [140, 123, 140, 68], (1, 2048): [119, 101, 106, 40],
    (3, 512): [141, 127, 149, 75], (3, 1024): [132, 113, 131, 56], (3, 2048): [102, 78, 87, 27],
    (7, 512): [138, 119, 146, 71], (7, 1024): [124, 100, 125, 46], (7, 2048): [86, 61, 78, 19],
}
SEED_73 = {  # (C, method) -> fps per S = 128, 256, 512, 1024; 800x800
    (1, "esm_z"): [410, 393, 374, 347], (1, "esm_t"): [569, 556, 527, 438],
    (3, "esm_z"): [369, 357, 345, 273], (3, "esm_t"): [547, 536, 495, 374],
    (5, "esm_z"): [358, 351, 338, 237], (5, "esm_t"): [544, 527, 474, 342],
}
SEED_81 = {  # (lookup, S) -> fps per lights 1, 10, 20, 40; M = 4
    ("mips", 128): [258, 48, 28, 18], ("mips", 256): [228, 44, 25, 15], ("mips", 512): [189, 38, 20, 13],
    ("mips", 1024): [110, 24, 5, None],
    ("sat", 128): [128, 15, 8.8, None], ("sat", 256): [110, 13, 7.5, None], ("sat", 512): [89, 11, 6.0, None],
    ("sat", 1024): [52, 3, 1.5, None],
}
SEED_002_HW = "NVIDIA GeForce 8800, Intel Core 2 Duo 6300"
SEED_2 = [  # scene, faces, resolution, samples S, time, M samples/s
    ("Local linear XYZ dragon", "280k", "320x240", 16, "45.0 ms", 27.3),
    ("", "", "1024x768", 16, "170.0 ms", 74.2),
    ("", "", "1024x768", 64, "600.0 ms", 83.8),
    ("", "", "1024x768", 625, "4860.0 ms", 101.1),
    ("Distant lat-long Buddha", "80k", "1024x768", 16, "190.0 ms", 66.2),
    ("", "", "1024x768", 64, "720.4 ms", 69.9),
    ("", "", "1024x768", 625, "6000.0 ms", 81.9),
    ("Random visibility Buddha", "80k", "1024x768", 16, "148.0 ms", 85.0),
    ("", "", "1024x768", 625, "3707.3 ms", 132.5),
    ("Coherent visibility Buddha", "80k", "1024x768", 16, "77.0 ms", 163.5),
    ("", "", "1024x768", 625, "261.3 ms", 190.4),
]


class Run:
    """The median entries of one sf_bench JSON, by family and arguments."""

    def __init__(self, paths):
        """Several files: a later file's entries replace an earlier one's (a family rerun after a
        change); the hardware line names every run."""
        self.contexts = []
        self.rows = {}
        for path in paths:
            d = json.load(open(path))
            self.contexts.append(d.get("context", {}))
            for b in d["benchmarks"]:
                if b.get("aggregate_name", "median") != "median" or b.get("error_occurred"):
                    continue
                name = b.get("run_name", b["name"])
                family = re.split(r"/[A-Za-z_]+:", name + "/x:")[0]
                args = {k: int(v) for k, v in re.findall(r"/([A-Za-z]+):(\d+)(?=/|$)", name) if k != "repeats"}
                self.rows[(family, tuple(sorted(args.items())))] = b

    def get(self, family, **args):
        return self.rows.get((family, tuple(sorted(args.items()))))

    def ms(self, family, **args):
        b = self.get(family, **args)
        if b is None:
            return None
        scale = {"ms": 1.0, "us": 1e-3, "ns": 1e-6, "s": 1e3}[b.get("time_unit", "ms")]
        return b["real_time"] * scale

    def fps(self, family, **args):
        t = self.ms(family, **args)
        return 1e3 / t if t else None

    def counter(self, family, key, **args):
        b = self.get(family, **args)
        return b.get(key) if b else None

    def hardware(self):
        c = self.contexts[0]
        dev = c.get("opencl_device", "?")
        cpus = c.get("num_cpus", "?")
        runs = "; ".join(f"{x.get('date', '?')} (copy {float(x.get('reference_copy_GBps', 0) or 0):.1f} GB/s)"
                         for x in self.contexts)
        return f"{dev}, {cpus} host CPUs; sf_bench runs of {runs}"


def num(x, digits=3):
    if x is None:
        return "—"
    if x >= 100:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def cell(ours, seed):
    return f"{num(ours)} ({num(seed)})"


def table_61(run):
    sizes = [256, 512, 1024, 2048]
    out = ["| C | | " + " | ".join(f"S = {s}²" for s in sizes) + " |", "| --- | --- |" + " ---: |" * len(sizes)]
    for c in (1, 3, 7):
        rows = (["PCF"] if c == 1 else []) + ["M = 4", "M = 8", "M = 16"]
        for r in rows:
            seed = SEED_61[(c, r)]
            ours = [run.fps("table6_1/pcf", size=s, C=1) if r == "PCF" else
                    run.fps("table6_1/csm", size=s, C=c, M=int(r.split()[-1])) for s in sizes]
            label = "no" if c == 1 else f"{c}x{c}"
            out.append(f"| {label} | {r} | " + " | ".join(cell(o, sd) for o, sd in zip(ours, seed)) + " |")
    return out


def table_71(run):
    methods = [("esm_t", "ESM-T"), ("esm_z", "ESM-Z"), ("vsm", "VSM"), ("csm", "CSM (M = 4)")]
    out = ["| C | S | " + " | ".join(m[1] for m in methods) + " |", "| --- | --- |" + " ---: |" * len(methods)]
    for c in (1, 3, 7):
        for s in (512, 1024, 2048):
            seed = SEED_71[(c, s)]
            ours = [run.fps("table7_1/" + m, size=s, C=c) for m, _ in methods]
            label = "no" if c == 1 else f"{c}x{c}"
            out.append(f"| {label} | {s}² | " + " | ".join(cell(o, sd) for o, sd in zip(ours, seed)) + " |")
    return out


def table_73(run):
    sizes = [128, 256, 512, 1024]
    out = ["| C | classification | " + " | ".join(f"S = {s}²" for s in sizes) + " |",
           "| --- | --- |" + " ---: |" * len(sizes)]
    for c in (1, 3, 5):
        for m, label in (("esm_z", "Z-max"), ("esm_t", "Threshold")):
            seed = SEED_73[(c, m)]
            cells = []
            for s, sd in zip(sizes, seed):
                fps = run.fps("table7_3/" + m, size=s, C=c)
                cls = run.counter("table7_3/" + m, "classify_ms", size=s, C=c)
                cells.append(f"{cell(fps, sd)}; {num(cls)} ms" if fps else "—")
            cl = "no" if c == 1 else f"{c}x{c}"
            out.append(f"| {cl} | {label} | " + " | ".join(cells) + " |")
    return out


def table_81(run):
    lights = [1, 10, 20, 40]
    out = ["| lookup | S | " + " | ".join(f"{n} light{'s' if n > 1 else ''}" for n in lights) + " |",
           "| --- | --- |" + " ---: |" * len(lights)]
    for lk, label in (("mips", "MM"), ("sat", "SAT")):
        for s in (128, 256, 512, 1024):
            seed = SEED_81[(lk, s)]
            ours = [run.fps("table8_1/cssm_" + lk, size=s, lights=n) for n in lights]
            out.append(f"| {label} | {s}² | " + " | ".join(cell(o, sd) for o, sd in zip(ours, seed)) + " |")
    return out


def table_2(run):
    fam = next((f for (f, _) in run.rows if f.startswith("coherent/query_") and "geometry" not in f), None)
    out = ["| visibility | ours: stack | ours: M samples/s (nearest; generalized PCF) | seed: S | seed: M samples/s |",
           "| --- | --- | ---: | --- | ---: |"]
    for rx, label, seeds in ((0, "random", SEED_2[7:9]), (1, "coherent", SEED_2[9:11])):
        if fam:
            near = run.counter(fam, "ns_per_query", filter=0, rx=rx)
            pcf = run.counter(fam, "ns_per_query", filter=1, rx=rx)
            ours = f"{num(1e3 / near if near else None)}; {num(1e3 / pcf if pcf else None)}"
            stack = fam.split("query_")[1]
        else:
            ours, stack = "—", "—"
        out.append(f"| {label} | {stack} | {ours} | {seeds[0][3]}, {seeds[1][3]} | {seeds[0][5]}, {seeds[1][5]} |")
    return out


def stage_ratios(run):
    """Issue 31's table: each stage of the default frame against its floor or peer."""
    out = ["| stage | figure | against | ratio |", "| --- | ---: | --- | ---: |"]

    def row(stage, fig, against, ratio):
        if fig is not None:
            out.append(f"| {stage} | {fig} | {against} | {ratio} |")

    for scene, lookup, label in ((2, 0, "backyard, bilinear (default)"), (2, 1, "backyard, mips"),
                                 (1, 0, "noise, coherent rx, bilinear"), (0, 0, "noise, random rx, bilinear"),
                                 (1, 1, "noise, coherent rx, mips"), (0, 1, "noise, random rx, mips")):
        f = "esm_classify/frame"
        r = run.counter(f, "classify_over_reconstruct", size=2048, scene=scene, lookup=lookup)
        if r is None:
            continue
        z = run.counter(f, "zmax_ms", size=2048, scene=scene, lookup=lookup)
        c = run.counter(f, "classify_ms", size=2048, scene=scene, lookup=lookup)
        rec = run.counter(f, "reconstruct_ms", size=2048, scene=scene, lookup=lookup)
        fl = run.counter(f, "flagged_pct", size=2048, scene=scene, lookup=lookup)
        row(f"ESM z-max classification, {label}, {num(fl)}% flagged",
            f"{num(z)} + {num(c)} ms", f"reconstruction {num(rec)} ms", f"{r:.2f}x")
    for r_ in (1, 3, 7, 15):
        ours = run.ms("blur/ours", size=2048, R=r_)
        cv = run.ms("blur/opencv_GaussianBlur", size=2048, R=r_)
        bw = run.counter("blur/ours", "bw_fraction", size=2048, R=r_)
        if ours is not None:
            row(f"blur 2048², R = {r_}", f"{num(ours)} ms", "copy bandwidth; cv::GaussianBlur",
                f"{num(bw)}; {num(cv / ours) if cv else '—'}x faster")
    for ch in (1, 4):
        bw = run.counter("mips/chain", "bw_fraction", size=2048, channels=ch)
        row(f"mip chain 2048², {ch} channel{'s' if ch > 1 else ''}", f"{num(run.ms('mips/chain', size=2048, channels=ch))} ms",
            "copy bandwidth", num(bw))
    # Reconstruction (issue 31 part 2), as the pipeline runs it (trilinear over the joined chain,
    # 16 receivers per work-item): coherent receivers against streaming their bytes at the copy
    # bandwidth (u, v, d, f read, the visibility written: 1 / bw_fraction), random ones against
    # the same 8 gathers per receiver in a kernel that does nothing else (`esm_reconstruct/bound`).
    rec = "esm_reconstruct/points_on_2048"
    coh = run.ms(rec, lookup=1, rx=1, vec=16, joined=1)
    bw = run.counter(rec, "bw_fraction", lookup=1, rx=1, vec=16, joined=1)
    if coh is not None and bw:
        row("reconstruction, 2048² trilinear, 1920x1080 coherent rx", f"{num(coh)} ms",
            "streaming its 20 B per receiver at copy bandwidth", f"{1 / bw:.2f}x the floor")
    rnd = run.ms(rec, lookup=1, rx=0, vec=16, joined=1)
    gather = run.ms("esm_reconstruct/bound", taps=8, rx=0)
    if rnd is not None and gather:
        row("reconstruction, 2048² trilinear, 1920x1080 random rx", f"{num(rnd)} ms",
            f"its 8 gathers alone {num(gather)} ms", f"{rnd / gather:.2f}x")
    fresh = run.counter("esm_classify/fresh_frame", "fresh_over_warm", size=2048)
    if fresh is not None:
        row("default frame on a new Pipeline and new buffers in a warm process, backyard",
            f"{num(run.ms('esm_classify/fresh_frame', size=2048))} ms", "the same frame warm", f"{fresh:.2f}x")
    one = run.ms("one_shot/filter", size=2048)
    if one is not None:  # scripts/one_shot.sh: a new process per run, interleaved with the bench's frame
        row("one `filter` run (a new process), backyard, the stages' device time", f"{num(one)} ms",
            f"the same frame in the bench {num(run.counter('one_shot/filter', 'bench_frame_ms', size=2048))} ms",
            f"{run.counter('one_shot/filter', 'over_bench', size=2048):.2f}x")
    for b in sorted(k for k in run.rows if k[0] == "esm_vs_opencv/ours"):
        args = dict(b[1])
        ours = run.ms("esm_vs_opencv/ours", **args)
        cv = run.ms("esm_vs_opencv/opencv", **args)
        rx = {0: ["random rx"], 1: ["coherent rx"]}.get(args.get("rx"), [])
        desc = ", ".join([f"{k} {v}" for k, v in sorted(args.items()) if k != "rx"] + rx)
        row(f"ESM pipeline vs the OpenCV pipeline ({desc})", f"{num(ours)} ms", "the OpenCV pipeline",
            f"{num(cv / ours) if cv and ours else '—'}x faster")
    return out


def doc(cpu, gpu):
    hw = f"- ours, CPU: {cpu.hardware()}\n" + (f"- ours, GPU: {gpu.hardware()}\n" if gpu else
                                                "- ours, GPU: not measured (no device run yet; `scripts/gpu/`)\n")
    sections = [
        ("Seed 000 Table 6.1: CSM, map size S x order M x convolution C, 1024x768 receivers", table_61,
         "csm with trilinear mips (the seed: 16x anisotropic trilinear, 8-bit basis; ours float32), "
         "C = 1 (none), 3x3 and 7x7 Gaussians (blur radius 1 and 3); PCF: our 2x2 PCF on the raw depth, "
         "the seed's hardware PCF. `table6_1/*`."),
        ("Seed 000 Table 7.1: ESM-T, ESM-Z, VSM and CSM, map size x convolution, 1920x1080 receivers", table_71,
         "trilinear mips; ESM-T: esm with threshold classification, ESM-Z: z-max; CSM at M = 4 (the seed does "
         "not state its order; 4 is its recommendation). `table7_1/*`."),
        ("Seed 000 Table 7.3: classification, map size x convolution, 800x800 receivers", table_73,
         "frame fps, then the classification's own device time (z-max pyramid, flags and 2x2 fall-back; "
         "the threshold test has no pyramid). `table7_3/*`."),
        ("Seed 000 Table 8.1: CSSM soft shadows, map size x number of lights, 1024x768 receivers", table_81,
         "cssm at M = 4 (the seed's), mips (MM) or the SAT; every light prefiltered and reconstructed in "
         "turn (one light's basis resident at a time), the lights' visibilities not summed; the seed's "
         "dashes are entries that did not fit its texture memory. `table8_1/*`."),
    ]
    lines = ["# Performance: the seeds' tables in their own shapes", "",
             "Written by `scripts/performance_tables.py` from sf_bench JSON (`make performance` runs the "
             "benchmarks and this script; bench/bench_tables.cpp says what each frame holds). Do not edit "
             "by hand: rerun it.", "",
             "Each cell is **ours (seed)** in frames per second. Ours is the device time of the filtering "
             "alone, from the rendered depth map to the visibility of every receiver (transform, blur, mip chain "
             "or SAT, classification, reconstruction) on the backyard scene; the seed's frames also rasterised "
             "and shaded their scene on a 2006 GPU. The comparison says where a 2-core CPU through PoCL stands "
             "against the seed's GPU, not which algorithm is faster.", "",
             "Hardware:", f"- seed 000: {SEED_000_HW}", f"- seed 002: {SEED_002_HW}", hw.rstrip(), ""]
    sections += [
        ("Seed 002 Table 2: coherent shadow map queries per second", table_2,
         "Ours: `coherent/query_*` (bench_coherent.cpp), 2^20 point queries against the compressed stack, "
         "random points and directions (random) or a grid in scan order with one direction per 4096 "
         "points (coherent); M samples/s = 1000 / ns per query. The seed's samples are Monte Carlo "
         "shadow tests inside a renderer at 1024x768 with S samples per pixel, N = 128² views, M = 128."),
        ("The default frame's stages against their floor or peer", stage_ratios,
         "Issue 31's table: the ESM classification against the reconstruction of the same receivers "
         "(`esm_classify/frame`, 2048² map, 1920x1080 receivers, R = 3), the blur and the mip chains against "
         "the device's measured copy bandwidth (`blur/ours`, `mips/chain`) and cv::GaussianBlur on both "
         "cores, the reconstruction against its streaming floor and its gathers (`esm_reconstruct/*`), a frame "
         "on fresh buffers against the warm one (`esm_classify/fresh_frame`), one `shadowfilter filter` process "
         "against the bench's frame (`scripts/one_shot.sh`, rounds interleaved), the ESM pipeline against the "
         "OpenCV one (`esm_vs_opencv/*`, both unclassified)."),
    ]
    for title, fn, note in sections:
        lines += [f"## {title}", "", note, ""]
        lines += ["### CPU", ""] + fn(cpu) + [""]
        if gpu:
            lines += ["### GPU", ""] + fn(gpu) + [""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cpu", required=True, nargs="+")
    ap.add_argument("--gpu", nargs="+")
    ap.add_argument("--out", default="docs/performance.md")
    ap.add_argument("--gpu-doc")
    a = ap.parse_args()
    try:
        cpu = Run(a.cpu)
        gpu = Run(a.gpu) if a.gpu else None
    except (OSError, ValueError, KeyError) as e:
        print(f"performance_tables: cannot read the bench JSON: {e}", file=sys.stderr)
        return 2
    text = doc(cpu, gpu) + "\n"
    with open(a.out + ".part", "w") as f:
        f.write(text)
    import os
    os.replace(a.out + ".part", a.out)
    if gpu and a.gpu_doc:
        page = open(a.gpu_doc).read()
        if GPU_BEGIN not in page or GPU_END not in page:
            print(f"performance_tables: {a.gpu_doc} has no {GPU_BEGIN} ... {GPU_END} section", file=sys.stderr)
            return 2
        body = "\n".join(["### GPU: the seeds' tables", ""] + [l for l in text.split("\n")[1:]])
        head, rest = page.split(GPU_BEGIN, 1)
        tail = rest.split(GPU_END, 1)[1]
        with open(a.gpu_doc + ".part", "w") as f:
            f.write(head + GPU_BEGIN + "\n" + body + "\n" + GPU_END + tail)
        os.replace(a.gpu_doc + ".part", a.gpu_doc)
    return 0


if __name__ == "__main__":
    sys.exit(main())
