#!/usr/bin/env python3
"""Validates every shader stage at build time with glslangValidator (Debian glslang-tools), the
way the plugin builds it at run time (shader_text.c): "#version 450 core", the variant's
#defines, one level of #include expanded. The variants are read from the C sources: every
volfx_gpu_program / volfx_gpu_compute / link_program call naming the file, with its defines
literal, or the snprintf format that fills its defines buffer (%d/%u/%s filled with 4/1/"").
A GLSL error fails the build as file:line: message, in the shader's own file. embed.py --validate
calls validate() before it writes a table; the command line writes a stamp.
usage: validate.py SHADER_ROOT STAMP C_SOURCE... [-- SHADER...]"""
import concurrent.futures
import os
import re
import subprocess
import sys
import tempfile

STAGE = {".vert": "vert", ".frag": "frag", ".comp": "comp"}


def c_string(lit):
    return bytes(lit, "utf-8").decode("unicode_escape")


def read_variants(csrc):
    """The define texts each shader path is built with, read from the C sources' calls."""
    variants = {}  # path -> set of define texts
    call = re.compile(r'(volfx_gpu_program|volfx_gpu_compute|link_program)\s*\(([^;]*?)\)\s*;', re.S)
    for f in csrc:
        text = open(f, encoding="utf-8").read()
        for m in call.finditer(text):
            args = m.group(2)
            paths = re.findall(r'"([a-z_]+/[a-z_]+\.(?:vert|frag|comp))"', args)
            if not paths:
                continue
            tail = args[args.rindex(paths[-1]) + len(paths[-1]) + 1:].strip().lstrip(",").strip()
            defs = set()
            lits = re.findall(r'"((?:\\.|[^"\\])*)"', tail)
            if m.group(1) == "link_program":  # the host's programs: (log, vert, frag, label), no defines
                pass
            elif lits:
                defs.add(c_string("".join(lits)))
            elif re.match(r"[a-z_]+$", tail):  # a buffer: the snprintf formats that fill it before here
                for fm in re.finditer(r"snprintf\(\s*%s\s*,[^,]+,\s*((?:\"(?:\\.|[^\"\\])*\"\s*)+)" % tail, text[: m.start()]):
                    fmt = c_string("".join(re.findall(r'"((?:\\.|[^"\\])*)"', fm.group(1))))
                    defs.add(re.sub(r"%[0-9]*[du]", "4", fmt).replace("%s", ""))
            if not defs:
                defs.add("")
            for p in paths:
                variants.setdefault(p, set()).update(defs)
    return variants


def check(root, job):
    rel, defs = job
    ext = os.path.splitext(rel)[1]
    src = open(os.path.join(root, rel), encoding="utf-8").read().split("\n")
    lines, where = ["#version 450 core"], [(rel, 0)]
    for d in defs.split("\n"):
        lines.append(d)
        where.append(("(defines)", 0))
    for n, l in enumerate(src, 1):
        m = re.match(r'\s*#include\s+"([^"]+)"', l)
        if m:
            for k, il in enumerate(open(os.path.join(root, m.group(1)), encoding="utf-8").read().split("\n"), 1):
                lines.append(il)
                where.append((m.group(1), k))
        else:
            lines.append("" if l.strip().startswith("#version") else l)
            where.append((rel, n))
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "s" + ext)
        open(path, "w").write("\n".join(lines) + "\n")
        r = subprocess.run(["glslangValidator", "-S", STAGE[ext], path], capture_output=True, text=True)
    out = []
    if r.returncode != 0:
        v = " [variant: %s]" % defs.strip().replace("\n", " ") if defs.strip() else ""
        for m in re.finditer(r"ERROR: \d+:(\d+): (.*)", r.stdout):
            i = int(m.group(1)) - 1
            f, ln = where[i] if i < len(where) else (rel, 0)
            out.append("%s:%d: %s%s" % (os.path.join(root, f), ln, m.group(2), v))
        if not out:
            out.append("%s: glslangValidator: %s" % (os.path.join(root, rel), r.stdout.strip()[-300:]))
    return out


def validate(root, csrc, files):
    """Checks every stage among files (.glsl pieces are only included) in each variant csrc builds
    it in; returns (the stage variants checked, the errors as file:line: message)."""
    variants = read_variants(csrc)
    jobs = []
    for rel in files:
        if os.path.splitext(rel)[1] not in STAGE:
            continue
        rel = os.path.relpath(os.path.abspath(rel), os.path.abspath(root)) if os.path.exists(rel) else rel
        for defs in sorted(variants.get(rel, {""})):
            jobs.append((rel, defs))
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        errors = [e for res in pool.map(lambda j: check(root, j), jobs) for e in res]
    return len(jobs), list(dict.fromkeys(errors))


def main():
    root, stamp = sys.argv[1], sys.argv[2]
    rest = sys.argv[3:]
    csrc = rest[: rest.index("--")] if "--" in rest else rest
    stages = rest[rest.index("--") + 1:] if "--" in rest else []
    runs, errors = validate(root, csrc, stages)
    if errors:
        sys.exit("\n".join(errors))
    open(stamp, "w").write("%d stage variants of %d files valid\n" % (runs, len(stages)))


if __name__ == "__main__":
    main()
