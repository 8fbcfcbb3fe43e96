#!/usr/bin/python3
"""Session 33's edge/flat split of an image's error (docs/performance.md, "Session 33").

usage: /usr/bin/python3 docs/probes/session33/edge_bias.py REFERENCE.png IMAGE.png [IMAGE.png ...]
           [--picture OUT.png X0 Y0 SIZE]

For each IMAGE (8-bit PNGs as vdbsplat writes them, same size as REFERENCE): the mean signed
difference over the covered pixels (reference R+G+B > 0.02) per channel, the RMS error over the
whole image, over the edge pixels (the reference's |∂x| + |∂y| of mean R, G, B above 0.05) and
over the covered pixels that are not edges. Needs numpy (Debian python3-numpy); reads PNGs with
zlib alone (no PIL), so it is slow (a few seconds at 400²).

--picture writes, side by side at 2× (nearest), the SIZE² pixels from (X0, Y0) of the reference,
then of each IMAGE and its signed error ×30 (mean of R, G, B; red: brighter than the reference,
blue: darker): docs/images/lod_checker_d5_error_s33.png.
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


def write_png(path, rgb):
    """An 8-bit RGB PNG of @p rgb (h × w × 3, values 0–255), rows unfiltered."""
    a = np.clip(rgb, 0, 255).astype(np.uint8)
    raw = b''.join(b'\x00' + row.tobytes() for row in a)
    chunk = lambda kind, body: (struct.pack('>I', len(body)) + kind + body +
                                struct.pack('>I', zlib.crc32(kind + body) & 0xffffffff))
    header = struct.pack('>IIBBBBB', a.shape[1], a.shape[0], 8, 2, 0, 0, 0)
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', header) + chunk(b'IDAT', zlib.compress(raw)) +
                           chunk(b'IEND', b''))


def picture(path, ref, images, x0, y0, size):
    window = (slice(y0, y0 + size), slice(x0, x0 + size))
    tiles = [ref[window] * 255]
    for image in images:
        d = (image - ref)[window].mean(2)
        error = np.zeros(d.shape + (3,))
        error[..., 0], error[..., 2] = np.clip(d * 30, 0, 1) * 255, np.clip(-d * 30, 0, 1) * 255
        tiles += [image[window] * 255, error]
    write_png(path, np.concatenate(tiles, 1).repeat(2, 0).repeat(2, 1))


def main():
    args = sys.argv[1:]
    out = None
    if '--picture' in args:
        at = args.index('--picture')
        out, x0, y0, size = args[at + 1], *map(int, args[at + 2:at + 5])
        args = args[:at] + args[at + 5:]
    if len(args) < 2:
        sys.exit(__doc__)
    sys.argv = [sys.argv[0]] + args
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
    if out:
        picture(out, ref, [read_png(path) for path in sys.argv[2:]], x0, y0, size)


if __name__ == '__main__':
    main()
