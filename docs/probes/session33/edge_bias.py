#!/usr/bin/python3
"""Session 33's edge/flat split of an image's error (docs/performance.md, "Session 33").

usage: /usr/bin/python3 docs/probes/session33/edge_bias.py REFERENCE.png IMAGE.png [IMAGE.png ...]

For each IMAGE (8-bit PNGs as vdbsplat writes them, same size as REFERENCE): the mean signed
difference over the covered pixels (reference R+G+B > 0.02) per channel, the RMS error over the
whole image, over the edge pixels (the reference's |∂x| + |∂y| of mean R, G, B above 0.05) and
over the covered pixels that are not edges. Needs numpy (Debian python3-numpy); reads PNGs with
zlib alone (no PIL), so it is slow (a few seconds at 400²).
"""
import struct
import sys
import zlib

import numpy as np


def read_png(path):
    data = open(path, 'rb').read()
    i, idat = 8, b''
    while i < len(data):
        n, = struct.unpack('>I', data[i:i + 4])
        kind, body = data[i + 4:i + 8], data[i + 8:i + 8 + n]
        i += 12 + n
        if kind == b'IHDR':
            w, h, depth, colour = struct.unpack('>IIBB', body[:10])
            if depth != 8 or colour not in (0, 2, 6):
                sys.exit(f'{path}: only 8-bit grey, RGB or RGBA PNGs')
        elif kind == b'IDAT':
            idat += body
    ch = {6: 4, 2: 3, 0: 1}[colour]
    raw, stride = zlib.decompress(idat), w * ch
    out, prev, p = np.zeros((h, stride), np.int32), [0] * stride, 0
    for y in range(h):
        f, row = raw[p], raw[p + 1:p + 1 + stride]
        p += 1 + stride
        cur = [0] * stride
        for x in range(stride):
            a = cur[x - ch] if x >= ch else 0
            c = prev[x - ch] if x >= ch else 0
            b = prev[x]
            if f == 0: v = row[x]
            elif f == 1: v = row[x] + a
            elif f == 2: v = row[x] + b
            elif f == 3: v = row[x] + (a + b) // 2
            else:
                q = a + b - c
                pa, pb, pc = abs(q - a), abs(q - b), abs(q - c)
                v = row[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)
            cur[x] = v & 255
        out[y], prev = cur, cur
    rgb = out.reshape(h, w, ch).astype(float) / 255.0
    return np.repeat(rgb, 3, 2) if ch == 1 else rgb[:, :, :3]


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    ref = read_png(sys.argv[1])
    covered = ref.sum(2) > 0.02
    grey = ref.mean(2)
    edge = (np.abs(np.diff(grey, axis=0, prepend=0)) + np.abs(np.diff(grey, axis=1, prepend=0))) > 0.05
    print(f'covered pixels {covered.sum()}, edge pixels {edge.sum()}')
    for path in sys.argv[2:]:
        d = read_png(path) - ref
        rms = lambda sel: float(np.sqrt((d[sel] ** 2).mean()))
        print(f'{path}: mean signed (covered) {np.round(d[covered].mean(0), 5)}, RMS all '
              f'{float(np.sqrt((d ** 2).mean())):.5f}, edges {rms(edge):.5f}, flat {rms(covered & ~edge):.5f}')


if __name__ == '__main__':
    main()
