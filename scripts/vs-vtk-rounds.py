#!/usr/bin/env python3
"""Rounds of ../shared/tools/vs-vtk.py, alternated between builds, summarised with intervals.

One vs-vtk.py run gives one median per view, and on a shared (paravirtualised) host VTK's own
median moves by up to 60 % from one run to the next (docs/performance.md, session 30). This
script runs ROUNDS rounds; in each, every build renders every volume through vs-vtk.py (the
builds' order rotates from round to round, so neither always goes first). It then reports, per
view: the median over rounds of the ratio vdbsplat / VTK, its range, a 90 % bootstrap interval of
that median (rounds resampled), and a verdict against issue 9's bars (at most 1.0 at the largest
distance, 2.0 at the others): "met" when the whole interval is at or below the bar, "not met"
when it is all above, else "undecided". With two or more builds, it also reports each build's
vdbsplat time against the first build's, paired round by round (VTK cancels out).

Usage (from the project root, after a build; vs-vtk.py's packages: python3-vtk9 python3-openvdb
python3-numpy xvfb xauth):

  scripts/vs-vtk-rounds.py [--build NAME=BIN ...] [--volume FILE.vdb:TF ...] [--rounds 3]
      [--runs 7] [--sizes 400,1024] [--distances 8,1,0.35] [--threads 2] [--extra "FLAGS"]
      [--out out/vs-vtk-rounds]
  scripts/vs-vtk-rounds.py --summarize [--out DIR]    # the tables again, from DIR's CSVs
  scripts/vs-vtk-rounds.py --self-test                # checks the statistics on made-up rounds

Defaults: --build build=build/vdbsplat; --volume volumes/engine.vdb:ct-bone and
volumes/checkerbox.vdb:grey. Without a DISPLAY, each vs-vtk.py run goes through xvfb-run.
Each round's CSV is DIR/BUILD/VOLUME/roundN/vs-vtk.csv (vs-vtk.py's own, with its PNGs).
--extra goes to vs-vtk.py's --extra (more render flags): --extra "--warmup 1" times a second render
in the same process, as VTK's side is timed (warm); without it each render is a fresh process.
"""
import argparse
import csv
import glob
import os
import random
import shutil
import statistics
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
CONFIDENCE = 0.90
RESAMPLES = 4000


def bootstrap_median_interval(values, seed=1):
    """The CONFIDENCE interval of the median of @p values by resampling them (percentiles)."""
    if len(values) == 1:
        return values[0], values[0]
    rng = random.Random(seed)
    medians = sorted(statistics.median(rng.choices(values, k=len(values))) for _ in range(RESAMPLES))
    tail = (1.0 - CONFIDENCE) / 2.0
    return medians[int(tail * (RESAMPLES - 1))], medians[int((1.0 - tail) * (RESAMPLES - 1))]


def verdict(lo, hi, bar):
    if hi <= bar:
        return "met"
    if lo > bar:
        return "not met"
    return "undecided"


def bar_for(distance, distances):
    """Issue 9: ≤ 1.0 at the far view (the largest --distance), ≤ 2.0 at the others."""
    return 1.0 if distance == max(distances) else 2.0


def read_rounds(out):
    """{(build, volume): [rows of each round]} from out/BUILD/VOLUME/roundN/vs-vtk.csv."""
    if not os.path.isdir(out):
        sys.exit(f"vs-vtk-rounds: error: {out}: no such directory")
    found = {}
    paths = [p for p in glob.glob(os.path.join(out, "*", "*", "round*", "vs-vtk.csv"))
             if os.path.basename(os.path.dirname(p))[5:].isdigit()]
    round_of = lambda path: int(os.path.basename(os.path.dirname(path))[5:])
    for path in sorted(paths, key=lambda p: (os.path.dirname(os.path.dirname(p)), round_of(p))):
        volume_dir = os.path.dirname(os.path.dirname(path))
        key = (os.path.basename(os.path.dirname(volume_dir)), os.path.basename(volume_dir))
        with open(path, newline="") as f:
            found.setdefault(key, []).append(list(csv.DictReader(f)))
    if not found:
        sys.exit(f"vs-vtk-rounds: error: {out}: no round CSVs (BUILD/VOLUME/roundN/vs-vtk.csv)")
    return found


def cells(rounds):
    """{(size, distance): [(vtk_ms, vdbsplat_ms) per round]} of one build and volume."""
    out = {}
    for rows in rounds:
        for row in rows:
            key = (int(row["size"]), float(row["distance"]))
            out.setdefault(key, []).append((float(row["vtk_ms"]), float(row["vdbsplat_ms"])))
    return out


def summarize(found, builds_order=None):
    builds = builds_order or sorted({b for b, _ in found})
    volumes = sorted({v for _, v in found})
    lines = []
    for volume in volumes:
        lines.append(f"\n{volume}: ratio vdbsplat / VTK, median over rounds [{int(CONFIDENCE * 100)} % interval] (range)\n")
        lines.append("| size | --distance | bar | " + " | ".join(builds) + " |")
        lines.append("|---|---|---|" + "---|" * len(builds))
        per_build = {b: cells(found.get((b, volume), [])) for b in builds}
        keys = sorted({k for c in per_build.values() for k in c}, key=lambda k: (k[0], -k[1]))
        distances = sorted({d for _, d in keys})
        for size, distance in keys:
            bar = bar_for(distance, distances)
            row = [str(size), f"{distance:g}", f"≤ {bar:.1f}"]
            for b in builds:
                samples = per_build[b].get((size, distance), [])
                if not samples:
                    row.append("–")
                    continue
                ratios = [s / v for v, s in samples]
                lo, hi = bootstrap_median_interval(ratios)
                row.append(f"{statistics.median(ratios):.2f} [{lo:.2f}, {hi:.2f}] ({min(ratios):.2f}–{max(ratios):.2f}, "
                           f"{len(ratios)} rounds) {verdict(lo, hi, bar)}; "
                           f"{statistics.median(v for v, _ in samples):.1f} / {statistics.median(s for _, s in samples):.1f} ms")
            lines.append("| " + " | ".join(row) + " |")
        if len(builds) > 1:
            first = builds[0]
            lines.append(f"\n{volume}: vdbsplat ms of each build / {first}'s, paired by round: median [interval]\n")
            lines.append("| size | --distance | " + " | ".join(builds[1:]) + " |")
            lines.append("|---|---|" + "---|" * (len(builds) - 1))
            for size, distance in keys:
                row = [str(size), f"{distance:g}"]
                base = per_build[first].get((size, distance), [])
                for b in builds[1:]:
                    pairs = list(zip(base, per_build[b].get((size, distance), [])))
                    if not pairs:
                        row.append("–")
                        continue
                    change = [n[1] / o[1] for o, n in pairs]
                    lo, hi = bootstrap_median_interval(change)
                    row.append(f"{statistics.median(change):.2f} [{lo:.2f}, {hi:.2f}]")
                lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def run_rounds(a):
    vs_vtk = a.vs_vtk
    if not os.path.exists(vs_vtk):
        sys.exit(f"vs-vtk-rounds: error: {vs_vtk}: not found (../shared/tools/vs-vtk.py beside the project)")
    builds = []
    for spec in a.build or ["build=build/vdbsplat"]:
        name, sep, binary = spec.partition("=")
        if not sep or not name or "/" in name:
            sys.exit(f"vs-vtk-rounds: error: --build {spec}: expected NAME=BIN (NAME without '/')")
        if not os.access(binary, os.X_OK):
            sys.exit(f"vs-vtk-rounds: error: --build {spec}: {binary} is not an executable")
        builds.append((name, binary))
    volumes = []
    for spec in a.volume or ["volumes/engine.vdb:ct-bone", "volumes/checkerbox.vdb:grey"]:
        path, sep, tf = spec.rpartition(":")
        if not sep or not os.path.exists(path):
            sys.exit(f"vs-vtk-rounds: error: --volume {spec}: expected FILE.vdb:TF with an existing file")
        volumes.append((path, tf))
    prefix = []
    if not os.environ.get("DISPLAY"):
        if not shutil.which("xvfb-run"):
            sys.exit("vs-vtk-rounds: error: no DISPLAY and no xvfb-run (apt-get install xvfb xauth)")
        prefix = ["xvfb-run", "-a", "-s", "-screen 0 2048x2048x24"]
    for r in range(1, a.rounds + 1):
        order = builds[(r - 1) % len(builds):] + builds[:(r - 1) % len(builds)]
        for name, binary in order:
            for path, tf in volumes:
                volume = os.path.splitext(os.path.basename(path))[0]
                out = os.path.join(a.out, name, volume, f"round{r}")
                cmd = prefix + ["/usr/bin/python3", vs_vtk, binary, path, "--tf", tf, "--distances", a.distances,
                                "--sizes", a.sizes, "--runs", str(a.runs), "--threads", str(a.threads), "--out", out]
                if a.extra:
                    cmd += ["--extra", a.extra]
                print(f"round {r}/{a.rounds}: {name} {volume}", file=sys.stderr, flush=True)
                done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                if done.returncode != 0:
                    sys.exit(f"vs-vtk-rounds: error: {' '.join(cmd)} failed:\n{done.stderr.strip()}")
    return [name for name, _ in builds]


def self_test():
    # A cell whose rounds are all below the bar is met; all above, not met; spread across it, undecided.
    lo, hi = bootstrap_median_interval([0.8, 0.85, 0.9, 0.95, 0.82])
    assert hi <= 1.0 and verdict(lo, hi, 1.0) == "met", (lo, hi)
    lo, hi = bootstrap_median_interval([1.3, 1.4, 1.5, 1.35, 1.45])
    assert lo > 1.0 and verdict(lo, hi, 1.0) == "not met", (lo, hi)
    lo, hi = bootstrap_median_interval([0.6, 1.4, 0.7, 1.5, 1.0])
    assert verdict(lo, hi, 1.0) == "undecided", (lo, hi)
    assert lo <= statistics.median([0.6, 1.4, 0.7, 1.5, 1.0]) <= hi
    assert bootstrap_median_interval([2.0]) == (2.0, 2.0)
    assert bar_for(8.0, [0.35, 1.0, 8.0]) == 1.0 and bar_for(1.0, [0.35, 1.0, 8.0]) == 2.0
    # The summary pairs builds by round: a build twice as slow reads 2.00 whatever VTK did.
    mk = lambda vtk, vs: [{"distance": "8", "size": "400", "vtk_ms": str(vtk), "vdbsplat_ms": str(vs)}]
    found = {("a", "v"): [mk(1.0, 2.0), mk(3.0, 4.0)], ("b", "v"): [mk(2.0, 4.0), mk(1.0, 8.0)]}
    text = summarize(found, ["a", "b"])
    assert "| 400 | 8 | 2.00 [2.00, 2.00] |" in text, text
    print("vs-vtk-rounds: self-test passed")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", action="append", help="NAME=BIN (repeat to alternate builds)")
    ap.add_argument("--volume", action="append", help="FILE.vdb:TF (repeat)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--sizes", default="400,1024")
    ap.add_argument("--distances", default="8,1,0.35")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--extra", default="", help="more vdbsplat render flags, one string (vs-vtk.py --extra)")
    ap.add_argument("--out", default="out/vs-vtk-rounds")
    ap.add_argument("--vs-vtk", default=os.path.join(ROOT, "..", "shared", "tools", "vs-vtk.py"))
    ap.add_argument("--summarize", action="store_true", help="only print the tables of --out's CSVs")
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        return self_test()
    if a.rounds < 1 or a.runs < 1:
        sys.exit("vs-vtk-rounds: error: --rounds and --runs must be at least 1")
    order = None if a.summarize else run_rounds(a)
    print(summarize(read_rounds(a.out), order))


if __name__ == "__main__":
    main()
