#!/usr/bin/env python3
"""Every numeric field the host hands the plugin has its row in volfx_ranges.h.

Reads the typedef'd structs of plugin/include/volfx/volfx.h, lists each float, double and integer
member (arrays too; a nested vfx_gpu_column by its own fields; not the typed header, pointers, callbacks, or
what the plugin writes: structs and members documented "out:" or filled by the plugin), and
requires a VFX_RANGE_TABLE row naming "struct.member" for each; a row naming a member volfx.h
does not have fails too, and so does a lab struct's row in the installed table. With the lab's
header and table (plugin/lab: volfx_lab.h, lab_ranges.h), every lab row must name a numeric member
of a lab struct (the lab rows the lab reads as numbers; its bit and method fields are checked by
their readers, by name).
usage: check_abi_ranges.py volfx.h volfx_ranges.h [volfx_lab.h lab_ranges.h]"""
import re
import sys

NUMERIC = {"float", "double", "uint32_t", "uint64_t", "int32_t", "int64_t"}  # vfx_gpu_column: its own fields
# structs the plugin fills for the host (no number of theirs is read)
OUTPUT_STRUCTS = {"vfx_stat", "vfx_stats", "vfx_light", "vfx_impact_event", "vfx_plugin_api", "vfx_chain"}


def fields(header_text):
    out = set()
    # an enum-typed member is a number too (vfx_struct_type is the typed header)
    enums = set(re.findall(r"typedef enum \w+ \{.*?\} (\w+);", header_text, re.S)) - {"vfx_struct_type"}
    for m in re.finditer(r"typedef struct (\w+) \{(.*?)\n\} \1;", header_text, re.S):
        name, body = m.group(1), m.group(2)
        if name in OUTPUT_STRUCTS:
            continue
        # one declaration per line in this header; a member's comment may say "out:"
        for line in body.split("\n"):
            code = re.sub(r"/\*.*?(\*/|$)", "", line).strip()
            if not code or code.startswith("*") or "(" in code or "*" in code:
                continue
            d = re.match(r"(?:const\s+)?(\w+)\s+(.*);$", code)
            if not d or (d.group(1) not in NUMERIC and d.group(1) not in enums):
                continue
            if re.search(r"/\*\s*out:", line):
                continue
            for member in d.group(2).split(","):
                member = re.sub(r"\[.*?\]", "", member).strip()
                if member:
                    out.add(f"{name}.{member}")
    return out


def main():
    header = open(sys.argv[1]).read()
    ranges = open(sys.argv[2]).read()
    want = fields(header)
    rows = set(re.findall(r'X\(\w+, "([\w.]+)"', ranges))
    missing = sorted(want - rows)
    stale = sorted(rows - want)
    for f in missing:
        print(f"{f}: a numeric field of volfx.h with no row in volfx_ranges.h")
    for f in stale:
        print(f"{f}: a row of volfx_ranges.h naming no field of volfx.h"
              + (" (a lab struct's: its row is the lab's, plugin/lab/lab_ranges.h)" if f.startswith("vfx_lab_") else ""))
    print(f"{len(want)} fields, {len(rows)} rows")
    if len(sys.argv) > 4:
        lab_fields = fields(open(sys.argv[3]).read())
        lab_rows = set(re.findall(r'X\(\w+, "([\w.]+)"', open(sys.argv[4]).read()))
        lab_stale = sorted(lab_rows - lab_fields)
        for f in lab_stale:
            print(f"{f}: a row of lab_ranges.h naming no numeric field of volfx_lab.h")
        print(f"{len(lab_fields)} lab fields, {len(lab_rows)} lab rows")
        if not lab_rows or len(lab_fields) < 4:
            print("no lab row or too few lab fields: the parser no longer reads the lab's files")
            return 1
        stale += lab_stale
    if len(want) < 90:
        print("fewer fields than expected: the parser no longer reads volfx.h")
        return 1
    return 1 if missing or stale else 0


if __name__ == "__main__":
    sys.exit(main())
