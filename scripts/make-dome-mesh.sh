#!/bin/sh
# make-dome-mesh.sh [OUT.vtu] [NPOINTS] [SEED] — the energy dome of the volume showcase: a
# Delaunay tet mesh (Debian's tetgen) of a unit half ball (y >= 0), points dense near its
# surface, with the point field "field": a shell peaking just inside the surface (what the
# transfer function lights) and a faint core. Written as a VTK XML .vtu, appended raw data,
# zlib-compressed (vtkZLibDataCompressor), Float32 points, Int32 connectivity.
# Default: sample_game/scenes/data/dome.vtu, 7000 points, seed 7 (deterministic).
set -eu
out=${1:-sample_game/scenes/data/dome.vtu}
n=${2:-7000}
seed=${3:-7}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 - "$tmp/pts.node" "$n" "$seed" <<'PY'
import math, random, sys
path, n, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rng = random.Random(seed)
pts = []
def unit():
    while True:
        v = [rng.uniform(-1, 1) for _ in range(3)]
        r = math.sqrt(sum(c * c for c in v))
        if 0.05 < r <= 1.0:
            return [c / r for c in v]
# the surface (hemisphere and floor ring) exactly, so the hull is the half ball
for i in range(n * 35 // 100):
    d = unit(); d[1] = abs(d[1]); pts.append(d)
for i in range(n * 5 // 100):
    a = rng.uniform(0, 2 * math.pi); r = math.sqrt(rng.uniform(0, 1))
    pts.append([r * math.cos(a), 0.0, r * math.sin(a)])
# the shell band r in [0.8, 1]
while len(pts) < n * 85 // 100:
    d = unit(); d[1] = abs(d[1]); r = rng.uniform(0.8, 1.0); pts.append([c * r for c in d])
# the core
while len(pts) < n:
    d = unit(); d[1] = abs(d[1]); r = rng.uniform(0, 1) ** (1 / 3) * 0.8; pts.append([c * r for c in d])
with open(path, "w") as f:
    f.write("%d 3 0 0\n" % len(pts))
    for i, p in enumerate(pts):
        f.write("%d %.7f %.7f %.7f\n" % (i, p[0], p[1], p[2]))
PY
tetgen -Q "$tmp/pts.node" >/dev/null
/usr/bin/python3 - "$tmp/pts.1.node" "$tmp/pts.1.ele" "$out" <<'PY'
import math, struct, sys, zlib
node, ele, out = sys.argv[1:4]
def rows(path):
    with open(path) as f:
        for line in f:
            line = line.split('#')[0].split()
            if line:
                yield line
it = rows(node); n = int(next(it)[0]); pts = [tuple(map(float, next(it)[1:4])) for _ in range(n)]
it = rows(ele); m = int(next(it)[0]); base = None; tets = []
for _ in range(m):
    r = next(it); t = list(map(int, r[1:5])); tets.append(t)
lo = min(min(t) for t in tets); tets = [[i - lo for i in t] for t in tets]
def field(p):
    r = math.sqrt(sum(c * c for c in p))
    return math.exp(-((r - 0.9) / 0.08) ** 2) + 0.1 * math.exp(-(r / 0.5) ** 2)
arrays = [("field", struct.pack("<%df" % n, *[field(p) for p in pts]), 'Float32', 1, "PointData"),
          ("Points", struct.pack("<%df" % (3 * n), *[c for p in pts for c in p]), 'Float32', 3, "Points"),
          ("connectivity", struct.pack("<%di" % (4 * m), *[i for t in tets for i in t]), 'Int32', 1, "Cells"),
          ("offsets", struct.pack("<%di" % m, *[4 * (k + 1) for k in range(m)]), 'Int32', 1, "Cells"),
          ("types", bytes([10]) * m, 'UInt8', 1, "Cells")]
blobs, offs, o = [], [], 0
for name, raw, *_ in arrays:
    z = zlib.compress(raw, 9)
    b = struct.pack("<4I", 1, len(raw), len(raw), len(z)) + z
    offs.append(o); o += len(b); blobs.append(b)
def da(i):
    name, raw, typ, comp, _ = arrays[i]
    return '<DataArray type="%s" Name="%s" NumberOfComponents="%d" format="appended" offset="%d"/>' % (typ, name, comp, offs[i])
xml = ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian" '
       'header_type="UInt32" compressor="vtkZLibDataCompressor">\n<UnstructuredGrid>\n'
       '<Piece NumberOfPoints="%d" NumberOfCells="%d">\n<PointData Scalars="field">%s</PointData>\n'
       '<Points>%s</Points>\n<Cells>%s%s%s</Cells>\n</Piece>\n</UnstructuredGrid>\n'
       '<AppendedData encoding="raw">\n_' % (n, m, da(0), da(1), da(2), da(3), da(4)))
with open(out, "wb") as f:
    f.write(xml.encode()); f.write(b"".join(blobs)); f.write(b"\n</AppendedData>\n</VTKFile>\n")
print("%s: %d points, %d tetrahedra" % (out, n, m))
PY
