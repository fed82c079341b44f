#!/bin/sh
# volfx-bench frame --scene FILE --dump-raw beams OUT.pfm writes a standard one-channel PFM of the
# right size whose values are finite and not all zero (the beams-only scene has light in view).
set -eu
bench=$1 scene=$2
out=${TMPDIR:-/tmp}/volfx-dump-$$.pfm
"$bench" frame --scene "$scene" --size 96x64 --frames 2 --dump-raw beams "$out" --json
python3 - "$out" <<'PY'
import math, struct, sys
data = open(sys.argv[1], "rb").read()
head = data.split(b"\n", 3)
assert head[0] == b"Pf", head[0]
w, h = map(int, head[1].split())
scale = float(head[2])
assert (w, h) == (96, 64) and scale < 0, (w, h, scale)
vals = struct.unpack("<%df" % (w * h), head[3][: 4 * w * h])
assert all(math.isfinite(v) for v in vals), "non-finite H"
assert max(vals) > 0, "no beam light in the dump"
print(f"pfm {w}x{h}, H max {max(vals):.4g}, lit pixels {sum(v > 0 for v in vals)}")
PY
rm -f "$out"
