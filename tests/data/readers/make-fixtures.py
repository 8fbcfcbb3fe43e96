#!/usr/bin/python3
"""tests/data/readers/make-fixtures.py — writes the small NRRD and VTI fixtures of the
readers' tests (tests/volume/test_nrrd.cpp, test_vti.cpp, tests/cli/test_cli_convert.cpp)
with other tools: VTK's vtkXMLImageDataWriter (python3-vtk9) for .vti in every mode, Teem's
`unu` (teem-apps, installed as teem-unu) for .nrrd/.nhdr, plus the same data as headerless
raw. The outputs are committed, so the tests need neither VTK nor Teem.
Owns: the fixture volume (7 x 5 x 4, x fastest, zeros included) and the file names.
Usage: /usr/bin/python3 tests/data/readers/make-fixtures.py   (apt-get install python3-vtk9 teem-apps)
"""
import math
import os
import struct
import subprocess

import vtk
from vtk.util import numpy_support
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DIMS = (7, 5, 4)
N = DIMS[0] * DIMS[1] * DIMS[2]
UNU = "teem-unu"


def values(kind):
    """The fixture's voxels in file order (x fastest); every fifth is 0 (background)."""
    out = []
    for i in range(N):
        if kind == "u8":
            v = 0 if i % 5 == 0 else (i * 37 + 11) % 256
        elif kind == "u16":
            v = 0 if i % 5 == 0 else (i * 2741 + 7) % 65536
        elif kind == "i16":
            v = 0 if i % 5 == 0 else (i * 911) % 65536 - 32768
        else:
            v = 0.0 if i % 5 == 0 else 2.0 * math.sin(i * 0.7)
        out.append(v)
    return out


NP = {"u8": np.uint8, "u16": np.uint16, "i16": np.int16, "f32": np.float32}
UNU_TYPE = {"u8": "uchar", "u16": "ushort", "i16": "short", "f32": "float"}


def write_raw(kind):
    path = os.path.join(HERE, f"vol_{kind}.raw")
    np.array(values(kind), dtype=NP[kind]).astype(np.dtype(NP[kind]).newbyteorder("<")).tofile(path)
    return path


def image(kind, spacing=(1, 1, 1), origin=(0, 0, 0), direction=None, extra=False):
    img = vtk.vtkImageData()
    img.SetDimensions(*DIMS)
    img.SetSpacing(*spacing)
    img.SetOrigin(*origin)
    if direction is not None:
        img.SetDirectionMatrix(direction)
    arr = numpy_support.numpy_to_vtk(np.array(values(kind), dtype=NP[kind]), deep=True)
    arr.SetName("density")
    if extra:  # an array before the wanted one, so "first array" and --array differ
        other = numpy_support.numpy_to_vtk(np.full(N, 3, dtype=np.uint8), deep=True)
        other.SetName("label")
        img.GetPointData().AddArray(other)
        img.GetPointData().AddArray(arr)
    else:
        img.GetPointData().SetScalars(arr)
    return img


def write_vti(name, img, mode, compressed, header64, base64_appended=False, block=None):
    w = vtk.vtkXMLImageDataWriter()
    w.SetFileName(os.path.join(HERE, name))
    w.SetInputData(img)
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
    if mode == "appended":
        w.SetEncodeAppendedData(1 if base64_appended else 0)
    if compressed:
        w.SetCompressorTypeToZLib()
    else:
        w.SetCompressorTypeToNone()
    if block:
        w.SetBlockSize(block)
    if header64:
        w.SetHeaderTypeToUInt64()
    else:
        w.SetHeaderTypeToUInt32()
    assert w.Write() == 1, name


def unu(*args, stdin=None):
    return subprocess.run([UNU, *args], input=stdin, check=True, capture_output=True).stdout


def write_nrrd(kind, raw, encoding, name, detached=False, space=True):
    """unu make (the header) then unu save (the encoding): what Teem itself writes."""
    make = ["make", "-i", raw, "-t", UNU_TYPE[kind], "-s", *map(str, DIMS), "-e", "raw", "-en", "little"]
    if space:
        make += ["-spc", "LPS", "-orig", "(-1,2,3.5)", "-dirs", "(0.5,0,0) (0,0.5,0) (0,0,1.25)"]
    else:
        make += ["-sp", "0.5", "0.5", "1.25"]
    nrrd = unu(*make, "-o", "-")
    out = os.path.join(HERE, name)
    if detached:  # unu save -o x.nhdr writes the header and a x.raw[.gz] data file beside it
        unu("save", "-f", "nrrd", "-e", encoding, "-i", "-", "-o", out, stdin=nrrd)
    else:
        unu("save", "-f", "nrrd", "-e", encoding, "-en", "big" if kind == "i16" else "little", "-i", "-",
            "-o", out, stdin=nrrd)


def main():
    raws = {k: write_raw(k) for k in ("u8", "u16", "i16", "f32")}
    # VTI: every data mode, compressed or not, both header widths.
    for kind in ("u8", "u16"):
        write_vti(f"{kind}_ascii.vti", image(kind), "ascii", False, False)
        for h in (32, 64):
            for z in (False, True):
                tag = f"{kind}_{{}}_{'zlib' if z else 'none'}_h{h}.vti"
                write_vti(tag.format("binary"), image(kind), "binary", z, h == 64)
                write_vti(tag.format("appended"), image(kind), "appended", z, h == 64)
                write_vti(tag.format("appended64"), image(kind), "appended", z, h == 64, base64_appended=True)
    write_vti("u16_blocks_zlib_h64.vti", image("u16"), "appended", True, True, block=64)  # several zlib blocks
    write_vti("u16_binary_blocks_zlib_h32.vti", image("u16"), "binary", True, False, block=48)
    write_vti("f32_geometry.vti", image("f32", (0.5, 0.5, 1.25), (-1, 2, 3.5)), "appended", True, False)
    write_vti("f32_ascii.vti", image("f32"), "ascii", False, False)
    write_vti("i16_binary.vti", image("i16"), "binary", False, False)
    rot = vtk.vtkMatrix3x3()
    for r, row in enumerate(((0, -1, 0), (1, 0, 0), (0, 0, 1))):  # 90 degrees about z
        for c, v in enumerate(row):
            rot.SetElement(r, c, v)
    write_vti("u8_rotated.vti", image("u8", (0.5, 0.5, 0.5), (1, 2, 3), rot), "binary", False, False)
    write_vti("u8_two_arrays.vti", image("u8", extra=True), "appended", False, False)
    # NRRD: attached and detached, raw and gzip; spacings or space directions + origin.
    for kind in ("u8", "u16", "i16", "f32"):
        write_nrrd(kind, raws[kind], "raw", f"{kind}_raw.nrrd")
        write_nrrd(kind, raws[kind], "gzip", f"{kind}_gzip.nrrd")
    write_nrrd("u16", raws["u16"], "raw", "u16_detached.nhdr", detached=True)
    write_nrrd("u16", raws["u16"], "gzip", "u16_detached_gz.nhdr", detached=True)
    write_nrrd("u8", raws["u8"], "raw", "u8_spacings.nrrd", space=False)


if __name__ == "__main__":
    main()
