#!/usr/bin/env python3
"""Pixel checks on Chromium screenshots, with the standard library only (no Pillow).

    png_check.py blank IMAGE            fails if the image is (nearly) one colour
    png_check.py differ IMAGE_A IMAGE_B fails if the two images are (nearly) the same

Prints the measured figures either way. Exit 0 pass, 1 fail, 2 unreadable input.
"""
import struct
import sys
import zlib


def read_png(path):
    """(width, height, rows of (r, g, b) tuples) of an 8-bit RGB or RGBA PNG."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, width, height, ctype = 8, b"", 0, 0, 0
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or ctype not in (2, 6) or interlace:
                raise ValueError(f"{path}: only 8-bit, non-interlaced RGB/RGBA is read")
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    bpp = 4 if ctype == 6 else 3
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        ftype, line = raw[start], bytearray(raw[start + 1 : start + 1 + stride])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        rows.append([tuple(line[x * bpp : x * bpp + 3]) for x in range(width)])
        prev = line
    return width, height, rows


def blank(path):
    w, h, rows = read_png(path)
    counts = {}
    for row in rows:
        for px in row:
            counts[px] = counts.get(px, 0) + 1
    background, most = max(counts.items(), key=lambda kv: kv[1])
    drawn = 1 - most / (w * h)
    print(f"{path}: {w}x{h}, {len(counts)} colours, {drawn:.1%} not background {background}")
    return drawn > 0.05 and len(counts) > 50


def differ(a, b):
    wa, ha, ra = read_png(a)
    wb, hb, rb = read_png(b)
    if (wa, ha) != (wb, hb):
        print(f"{a} and {b} differ in size")
        return True
    changed = sum(
        1
        for y in range(ha)
        for x in range(wa)
        if sum(abs(p - q) for p, q in zip(ra[y][x], rb[y][x])) > 24
    )
    share = changed / (wa * ha)
    print(f"{a} vs {b}: {share:.2%} of pixels changed")
    return share > 0.002


def main(argv):
    try:
        if len(argv) == 3 and argv[1] == "blank":
            return 0 if blank(argv[2]) else 1
        if len(argv) == 4 and argv[1] == "differ":
            return 0 if differ(argv[2], argv[3]) else 1
    except (OSError, ValueError, zlib.error) as e:
        print(e)
        return 2
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
