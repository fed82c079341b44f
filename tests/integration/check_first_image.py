#!/usr/bin/env python3
"""The "first image in 15 minutes" walkthrough of docs/integration.md is a program: its blocks
marked <!-- first_image.c --> are cut out in order, compiled against the plugin like the page
says (-I the ABI header, -lvolfx, libepoxy for the host's own GL) and run; the image must show
the water and the beam over the sky.
usage: check_first_image.py SOURCE_ROOT LIBVOLFX [SANITIZE]   (77: no GL context)"""
import os, re, subprocess, sys, tempfile

root, lib = sys.argv[1], os.path.abspath(sys.argv[2])
san = sys.argv[3] if len(sys.argv) > 3 and sys.argv[3] != "none" else None
page = open(os.path.join(root, "docs", "integration.md")).read()
blocks = re.findall(r"<!-- first_image\.c -->\s*```c\n(.*?)```", page, re.S)
if len(blocks) < 3:
    sys.exit("found %d first_image.c blocks in docs/integration.md" % len(blocks))
src = "".join(blocks)
print("first_image.c: %d blocks, %d lines" % (len(blocks), src.count("\n")))
with tempfile.TemporaryDirectory() as d:
    c = os.path.join(d, "first_image.c")
    open(c, "w").write(src)
    epoxy = subprocess.run(["pkg-config", "--cflags", "--libs", "epoxy"], capture_output=True, text=True,
                           check=True).stdout.split()
    cmd = ["cc", "-std=c11", "-Wall", "-Wextra", "-Werror", "-D_POSIX_C_SOURCE=200809L", c,
           "-I" + os.path.join(root, "plugin", "include"), lib, "-Wl,-rpath," + os.path.dirname(lib)] + epoxy + \
          ["-lm", "-o", os.path.join(d, "first_image")] + (["-fsanitize=" + san] if san else [])
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode:
        sys.exit("the walkthrough does not compile:\n" + r.stderr)
    r = subprocess.run([os.path.join(d, "first_image")], cwd=d, capture_output=True, text=True)
    print(r.stdout + r.stderr)
    if r.returncode == 77:
        sys.exit(77)
    if r.returncode:
        sys.exit("first_image exited %d" % r.returncode)
    data = open(os.path.join(d, "first_image.ppm"), "rb").read()
head, px = data.split(b"\n", 1)
w, h = int(head.split()[1]), int(head.split()[2])
sky = px[0:3]  # the top-left corner is sky
differ = sum(px[3 * i:3 * i + 3] != sky for i in range(w * h))
bright = sum(min(px[3 * i:3 * i + 3]) > 200 for i in range(w * h))  # the beam's white core
print("%d of %d pixels differ from the sky, %d near white" % (differ, w * h, bright))
# the water block covers about a tenth of the image, the beam's core a few hundred pixels
sys.exit(0 if differ > w * h // 20 and bright > 100 else 1)
