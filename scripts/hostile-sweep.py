#!/usr/bin/python3
"""Hostile-input sweep of the command line: about 155 bad flags, files, outputs and transfer
functions, each run through the real binary. Every case must exit 0, or 1 with exactly one
'vdbsplat: error:' line, within its time limit (20 s unless stated), leave no temporaries, leave
no output behind on error, and never change its input volume. Prints each failure and a count.
Usage: /usr/bin/python3 scripts/hostile-sweep.py build/vdbsplat      (a scratch folder in /tmp)
Known to fail (docs/robustness.md): --size 16384x16384 (a 47 s render), a bare `vdbsplat` (usage, exit 2)."""
import os, subprocess, sys, shutil, json, hashlib, stat, tempfile
B = os.path.abspath(sys.argv[1]); W = tempfile.mkdtemp(prefix="vdbsplat-hostile-")
os.chdir(W)
def run(args, t=20, stdin=None):
    try:
        p = subprocess.run([B] + args, capture_output=True, text=True, timeout=t, stdin=stdin or subprocess.DEVNULL)
        return p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired:
        return "TIMEOUT", "", ""
subprocess.run([B, "generate", "sphere", "-o", "s.vdb", "--res", "16"], capture_output=True)
subprocess.run([B, "generate", "checkerbox", "-o", "cb.vdb", "--res", "20"], capture_output=True)
open("empty.vdb", "w").close(); open("text.vdb", "w").write("hello\n")
data = open("s.vdb", "rb").read(); open("trunc.vdb", "wb").write(data[: len(data) // 2])
os.makedirs("adir.vdb", exist_ok=True)
if not os.path.exists("fifo.vdb"): os.mkfifo("fifo.vdb")
open("deep.json", "w").write("[" * 200000 + "]" * 200000)
open("deepobj.json", "w").write('{"a":' * 100000 + "1" + "}" * 100000)
open("bad.json", "w").write("{")
open("nan.json", "w").write('{"color":[[0,1,1,1],[1,1,1,1]],"extinction":[[0,NaN],[1,1]]}')
open("big.json", "w").write('{"color":[[0,1,1,1],[1,1,1,1]],"extinction":[[0,1e308],[1,1e308]]}')
open("huge.json", "w").write('{"color":[' + ",".join("[%f,1,1,1]" % (i / 1e6) for i in range(1000001)) + '],"extinction":[[0,1],[1,1]]}')
open("nonmono.json", "w").write('{"color":[[1,1,1,1],[0,1,1,1]],"extinction":[[0,1],[1,1]]}')
open("neg.json", "w").write('{"color":[[0,1,1,1],[1,1,1,1]],"extinction":[[0,-1],[1,1]]}')
open("empty.json", "w").write('{}')
open("arr.json", "w").write('[]')
open("pv.json", "w").write('[{"RGBPoints":[0,1,1]}]')
open("pv2.json", "w").write('[{"RGBPoints":[]}]')
open("pv3.json", "w").write('[{"RGBPoints":[0,1,1,1, 1,1,1,1], "Points":[0,0,0.5,0, 1,1e40,0.5,0]}]')
cases = []
R = ["render", "s.vdb", "-o", "o.png"]
for flag, vals in {
    "--size": ["0x0", "1x1", "-5x5", "99999x1", "16384x16385", "abcx1", "10", "10x", "x10", "1e3x1e3", "4294967297x2", "16384x16384"],
    "--fov": ["0", "180", "179.9999", "-30", "nan", "inf", "1e-300", "abc", ""],
    "--distance": ["0", "-1", "nan", "inf", "1e-300", "1e300", "1e-12"],
    "--threshold": ["-1", "nan", "inf", "0", "1e300"],
    "--lod": ["-1", "nan", "inf", "1e300"],
    "--threads": ["-1", "0", "99999999", "1.5", "nan"],
    "--spp": ["0", "-1", "1e9", "1025", "nan"],
    "--eye": ["nan,0,0", "1,2", "1,2,3,4", "0,0,0", "1e300,0,0", "inf,0,0", "8,8,8"],
    "--view-dir": ["0,0,0", "nan,1,0", "1e-320,0,0"],
    "--up": ["0,0,0", "1,1,1"],
    "--tf": ["nope", "deep.json", "deepobj.json", "bad.json", "nan.json", "big.json", "nonmono.json", "neg.json", "empty.json", "arr.json", "pv.json", "pv2.json", "pv3.json", "adir.vdb", "fifo.vdb", "/dev/zero", "huge.json"],
    "--mode": ["nope", ""],
    "--footprint": ["nope"],
    "--grid": ["nope", ""],
    "--subpixels": ["0", "9", "1e9"],
    "--max-voxels": ["0", "-1", "1e30"],
    "--tables": ["", "/nonexistent", "s.vdb", "/dev/null"],
    "--light": ["nan,0,0", "0,0,0"],
    "--shininess": ["-1", "nan", "1e30"],
}.items():
    for v in vals:
        extra = ["--mode", "reference", "--spp", "1"] if flag in ("--spp",) else []
        cases.append((R + [flag, v] + extra, None))
cases.append((R + ["--eye", "8,8,8", "--look-at", "8,8,8"], None))
cases.append((R + ["--eye", "0,0,0", "--up", "0,0,1", "--look-at", "0,0,5"], None))
cases.append((R + ["--view-dir", "0,0,1", "--up", "0,0,1"], None))
cases.append((R + ["--size"], None)); cases.append((R + ["--bogus"], None)); cases.append((R + ["extra"], None))
cases.append((R + ["--size", "8x8", "--size", "9x9"], None))
for inp in ["missing.vdb", "empty.vdb", "text.vdb", "trunc.vdb", "adir.vdb", "fifo.vdb", "/dev/zero", "/dev/null"]:
    cases.append((["render", inp, "-o", "o.png"], None)); cases.append((["info", inp], None))
for out in ["adir.vdb", "nodir/o.png", "o.txt", "o", "/dev/full", "s.vdb", "o.PNG", "fifo.vdb", "o\nx.png", ".png", "adir.vdb/"]:
    cases.append((["render", "s.vdb", "-o", out, "--size", "16x16"], None))
cases.append((["render", "s.vdb", "-o", "o.png", "--stats", "adir.vdb"], None))
cases.append((["render", "s.vdb", "-o", "o.png", "--stats", "s.vdb"], None))
cases.append((["render", "s.vdb", "-o", "s.vdb"], None))
cases.append((["compare", "s.vdb", "s.vdb"], None)); cases.append((["compare", "fifo.vdb", "o.png"], None))
cases.append((["compare", "/dev/zero", "/dev/zero"], None))
cases.append((["generate", "cloud", "--active", "1e12", "-o", "c.vdb"], None))
cases.append((["generate", "cloud", "--active", "-1", "-o", "c.vdb"], None))
cases.append((["generate", "sphere", "--res", "100000", "-o", "c.vdb"], None))
cases.append((["generate", "sphere", "--res", "0", "-o", "c.vdb"], None))
cases.append((["generate", "nope", "-o", "c.vdb"], None))
cases.append((["generate", "sphere", "-o", "s.vdb", "--res", "abc"], None))
cases.append((["convert", "text.vdb", "-o", "c.vdb", "--dims", "100000,100000,100000", "--type", "uint8"], None))
cases.append((["convert", "text.vdb", "-o", "c.vdb", "--dims", "0,1,1", "--type", "uint8"], None))
cases.append((["convert", "/dev/zero", "-o", "c.vdb", "--dims", "2000,2000,2000", "--type", "uint8"], 30))
cases.append((["convert", "fifo.vdb", "-o", "c.vdb", "--dims", "2,2,2", "--type", "uint8"], None))
cases.append((["convert", "s.vdb", "-o", "s.vdb", "--dims", "2,2,2", "--type", "uint8"], None))
cases.append((["bench", "s.vdb", "--runs", "0"], None)); cases.append((["bench", "s.vdb", "--runs", "1e9"], 30))
cases.append((["animate", "s.vdb", "-o", "anim", "--frames", "0"], None))
cases.append((["animate", "s.vdb", "-o", "anim", "--frames", "1e9", "--size", "8x8"], 30))
cases.append((["animate", "s.vdb", "-o", "anim", "--from", "nan", "--to", "1", "--frames", "2"], None))
cases.append(([], None)); cases.append((["nope"], None)); cases.append((["render"], None))
fails = 0
h = hashlib.sha256(open("s.vdb", "rb").read()).hexdigest()
for args, t in cases:
    for f in ("o.png", "c.vdb"):
        if os.path.exists(f): os.remove(f)
    rc, out, err = run(args, t or 20)
    lines = [l for l in err.splitlines() if l.strip()]
    bad = []
    if rc == "TIMEOUT": bad.append("timeout")
    elif rc not in (0, 1): bad.append(f"rc={rc}")
    if rc == 1 and (len(lines) != 1 or not lines[0].startswith("vdbsplat: error:")): bad.append(f"stderr {len(lines)} lines")
    if rc == 1 and os.path.exists("o.png") and "o.png" in args: bad.append("output left")
    tmps = [f for f in os.listdir(".") if ".tmp" in f or f.startswith(".vdbsplat")]
    if tmps: bad.append(f"temporaries {tmps}"); [os.remove(x) for x in tmps if os.path.isfile(x)]
    if hashlib.sha256(open("s.vdb", "rb").read()).hexdigest() != h: bad.append("INPUT CLOBBERED"); subprocess.run([B, "generate", "sphere", "-o", "s.vdb", "--res", "16"], capture_output=True); h = hashlib.sha256(open("s.vdb", "rb").read()).hexdigest()
    if bad:
        fails += 1
        print("FAIL", " ".join(repr(a) if (" " in a or "\n" in a or a == "") else a for a in args), "->", bad, "|", (lines[:3] if lines else ""), flush=True)
print(f"{len(cases)} cases, {fails} failed")
shutil.rmtree(W, ignore_errors=True)
