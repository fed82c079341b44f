#!/usr/bin/env python3
"""What the water adds to the beams' light over its surface (docs/water-look.md, "Beams in the water").

Renders a scene four times (water shown / hidden x beams on / off, --no-beams) and the water's ray
distance (--dump-raw water: the surface is where it is >= 0), then per pixel of the surface

    added = (L(water, beams) - L(water, no beams)) - (L(hidden, beams) - L(hidden, no beams))

with L the Rec. 709 luminance of the tone-mapped sRGB PNG (0..1). Prints its median, 95th
percentile and mean. Pure Python (zlib PNG and PFM readers): no numpy.

    scripts/water-beams-light.py GAME SCENE FRAMES WxH [--plugin LIB]
"""
import os
import struct
import subprocess
import sys
import tempfile
import zlib


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and ctype in (2, 6), "8-bit RGB(A) only"
            bpp = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    lum = []
    for line in rows:
        for x in range(w):
            r, g, b = line[x * bpp], line[x * bpp + 1], line[x * bpp + 2]
            lum.append((0.2126 * r + 0.7152 * g + 0.0722 * b) / 255.0)
    return w, h, lum


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        n = w * h * (3 if kind == b"PF" else 1)
        vals = struct.unpack(("<" if scale < 0 else ">") + "%df" % n, f.read(4 * n))
    if kind == b"PF":
        vals = vals[::3]
    # PFM rows run bottom to top; the PNG's top to bottom
    return [vals[(h - 1 - y) * w + x] for y in range(h) for x in range(w)]


def main():
    args = sys.argv[1:]
    plugin = []
    if "--plugin" in args:
        i = args.index("--plugin")
        plugin = ["--plugin", args[i + 1]]
        del args[i:i + 2]
    game, scene, frames, size = args
    tmp = tempfile.mkdtemp(prefix="wbl")
    base = [game, "--headless", "--scene", scene, "--frames", frames, "--size", size] + plugin
    img = {}
    for water in ("shown", "hidden"):
        for beams in ("on", "off"):
            png = os.path.join(tmp, "%s-%s.png" % (water, beams))
            cmd = base + ["--png", png] + (["--hide-water"] if water == "hidden" else []) + \
                (["--no-beams"] if beams == "off" else [])
            if water == "shown" and beams == "on":
                cmd += ["--dump-raw", "water", os.path.join(tmp, "water.pfm")]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            img[water, beams] = read_png(png)[2]
    dist = read_pfm(os.path.join(tmp, "water.pfm"))
    added = [(img["shown", "on"][i] - img["shown", "off"][i]) - (img["hidden", "on"][i] - img["hidden", "off"][i])
             for i in range(len(dist)) if dist[i] >= 0]
    if not added:
        sys.exit("no water pixel in the frame")
    added.sort()
    q = lambda p: added[min(int(p * len(added)), len(added) - 1)]
    print("%s frame %s %s: %d water pixels; beams' light added by the water: median %.4f, p95 %.4f, mean %.4f"
          % (scene, frames, size, len(added), q(0.5), q(0.95), sum(added) / len(added)))


if __name__ == "__main__":
    main()
