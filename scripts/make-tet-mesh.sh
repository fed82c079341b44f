#!/bin/sh
# make-tet-mesh.sh [OUTBASE] [NPOINTS] [SEED] — a Delaunay tet mesh of NPOINTS points sampled
# inside a torus (R=2, r=0.8) with one smooth node attribute, by Debian's tetgen.
# Writes OUTBASE.node and OUTBASE.ele (default build/tetmesh/torus; 60000 points -> >300k tets).
set -eu
out=${1:-build/tetmesh/torus}
n=${2:-60000}
seed=${3:-1}
mkdir -p "$(dirname "$out")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 - "$tmp/pts.node" "$n" "$seed" <<'PY'
import math, random, sys
path, n, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rng = random.Random(seed)  # deterministic: same seed, same mesh
R, r = 2.0, 0.8
pts = []
while len(pts) < n:
    x, y, z = (rng.uniform(-R - r, R + r), rng.uniform(-R - r, R + r), rng.uniform(-r, r))
    q = math.hypot(x, y) - R
    if q * q + z * z < r * r:
        # smooth field: a wave around the ring times a radial falloff in the tube
        s = (1.0 + math.sin(3.0 * math.atan2(y, x))) * math.exp(-(q * q + z * z) / (0.5 * r * r))
        pts.append((x, y, z, s))
with open(path, "w") as f:
    f.write("%d 3 1 0\n" % n)
    for i, (x, y, z, s) in enumerate(pts):
        f.write("%d %.9g %.9g %.9g %.9g\n" % (i, x, y, z, s))
PY
tetgen -Q "$tmp/pts.node" >/dev/null
mv "$tmp/pts.1.node" "$out.node"
mv "$tmp/pts.1.ele" "$out.ele"
head -n 1 "$out.ele" | awk -v o="$out" '{print o ": " $1 " tetrahedra"}'
