#!/usr/bin/env python3
"""The docs are reference pages: every relative link and image in README.md, CONTRIBUTING.md
and docs/*.md points at a file that exists (at a heading, for an anchor), every docs/<page>.md
they name exists, no page in docs/ is over 400 lines, and no heading is keyed to an issue, a
round, a stop, a date or a superseded state (history stays in git).
usage: check_docs.py SOURCE_ROOT"""
import os
import re
import sys

MAX_LINES = 400
DIARY = re.compile(r"\b(issues?|rounds?|stops?|superseded|state of the work)\b|\b20\d\d\b", re.I)
# A superseded section stays in git, not on the page: the word is refused anywhere in docs/.
SUPERSEDED = re.compile(r"\bsupersed", re.I)
LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def anchors(path):
    """The anchors of a page's headings as GitHub makes them: lower case, punctuation but '-' and
    '_' dropped, spaces as '-', a repeated heading suffixed -1, -2, ..."""
    out, seen, fence = set(), {}, False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.lstrip().startswith("```"):
                fence = not fence
                continue
            m = None if fence else re.match(r"#+\s+(.*)", line)
            if m:
                a = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower()).replace(" ", "-")
                n = seen.get(a, -1) + 1
                seen[a] = n
                out.add(a if n == 0 else "%s-%d" % (a, n))
    return out


def pages(root):
    out = [p for p in ("README.md", "CONTRIBUTING.md") if os.path.isfile(os.path.join(root, p))]
    out += sorted("docs/" + f for f in os.listdir(os.path.join(root, "docs")) if f.endswith(".md"))
    return out


def check(root, rel):
    fails = []
    path = os.path.join(root, rel)
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    ruled = rel.startswith("docs/")
    if ruled and len(lines) > MAX_LINES:
        fails.append("%s: %d lines (at most %d: split it into topic pages)" % (rel, len(lines), MAX_LINES))
    fence = False
    for n, line in enumerate(lines, 1):
        if line.lstrip().startswith("```"):
            fence = not fence
            continue
        if fence:
            continue
        if ruled and line.startswith("#") and DIARY.search(line):
            fails.append("%s:%d: heading keyed to an issue/round/stop/date: %s" % (rel, n, line.strip()))
        if ruled and SUPERSEDED.search(line):
            fails.append("%s:%d: a superseded part (history stays in git): %s" % (rel, n, line.strip()))
        for page in re.findall(r"(?<![\w/.-])docs/[\w.-]+\.md\b", line):
            if not os.path.isfile(os.path.join(root, page)):
                fails.append("%s:%d: names %s, which does not exist" % (rel, n, page))
        for target in LINK.findall(line):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
                continue  # a URL
            if target.startswith("#"):
                if target[1:] not in anchors(path):
                    fails.append("%s:%d: no heading for the anchor %s" % (rel, n, target))
                continue
            file_part, _, anchor = target.partition("#")
            dest = os.path.normpath(os.path.join(os.path.dirname(path), file_part))
            if not os.path.exists(dest):
                fails.append("%s:%d: broken link %s" % (rel, n, target))
            elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                fails.append("%s:%d: no heading for the anchor of %s" % (rel, n, target))
    return fails


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: check_docs.py SOURCE_ROOT")
    root = sys.argv[1]
    fails = []
    for rel in pages(root):
        fails += check(root, rel)
    for f in fails:
        print(f)
    print("%d pages, %d problems" % (len(pages(root)), len(fails)))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
