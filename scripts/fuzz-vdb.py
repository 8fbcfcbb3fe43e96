#!/usr/bin/env python3
"""Fuzz vdbsplat's VDB reading with damaged copies of one file.

Usage: scripts/fuzz-vdb.py FILE.vdb SEED COUNT [BINARY]

Each trial writes a copy of FILE.vdb with 1-8 random bytes replaced, or cut short, or one
8-byte field overwritten (all zeros, all ones, 2^62), then runs `vdbsplat info` and a 32x32
`vdbsplat render` on it. Every run must exit 0, or exit 1 with exactly one stderr line, within
20 seconds. Offending files are kept as fuzz-bad-N.vdb in the working folder; the last line
says how many runs misbehaved. Needs python3; not part of the test suite (it takes minutes).
"""
import os
import random
import subprocess
import sys
import tempfile


def mutate(data: bytes, rng: random.Random) -> bytes:
    b = bytearray(data)
    kind = rng.random()
    if kind < 0.5:
        for _ in range(rng.randint(1, 8)):
            b[rng.randrange(len(b))] = rng.randrange(256)
    elif kind < 0.8:
        b = b[: rng.randrange(len(b))]
    else:
        i = rng.randrange(len(b) - 8)
        b[i : i + 8] = rng.choice([b"\xff" * 8, b"\x00" * 8, (2**62).to_bytes(8, "little")])
    return bytes(b)


def main() -> int:
    if len(sys.argv) < 4:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    source, seed, count = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    binary = sys.argv[4] if len(sys.argv) > 4 else os.path.join(os.path.dirname(__file__), "..", "build", "vdbsplat")
    rng = random.Random(seed)
    data = open(source, "rb").read()
    bad = 0
    with tempfile.TemporaryDirectory(prefix="vdbsplat-fuzz-") as tmp:
        damaged, image = os.path.join(tmp, "damaged.vdb"), os.path.join(tmp, "out.png")
        for trial in range(count):
            mutated = mutate(data, rng)
            with open(damaged, "wb") as f:
                f.write(mutated)
            for args in (["info", damaged], ["render", damaged, "-o", image, "--size", "32x32"]):
                try:
                    r = subprocess.run([binary] + args, capture_output=True, timeout=20)
                    ok = r.returncode == 0 or (r.returncode == 1 and r.stderr.count(b"\n") == 1)
                    verdict = f"exit {r.returncode}: {r.stderr[:300]!r}"
                except subprocess.TimeoutExpired:
                    ok, verdict = False, "no answer in 20 s"
                if not ok:
                    bad += 1
                    print(f"trial {trial} {args[0]}: {verdict}")
                    with open(f"fuzz-bad-{trial}.vdb", "wb") as f:
                        f.write(mutated)
    print(f"{count} damaged files, {2 * count} runs, {bad} misbehaved")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
