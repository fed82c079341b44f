#!/usr/bin/env python3
"""The table of log ids in docs/abi.md, made from VFX_LOG_ID_LIST in volfx.h (the one list).

  log-ids-table.py               prints the table (markdown)
  log-ids-table.py --write DOC   puts it between DOC's <!-- log-ids --> markers
  log-ids-table.py --check DOC   exits 1 when DOC's table differs from the header's list
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
HEADER = ROOT / 'plugin/include/volfx/volfx.h'
BEGIN, END = '<!-- log-ids -->', '<!-- /log-ids -->'


def ids(header_text):
    """(name, value, meaning) of each X(NAME, value) /* meaning */ entry of VFX_LOG_ID_LIST."""
    block = header_text[header_text.index('#define VFX_LOG_ID_LIST(X)'):]
    block = block[:block.index('\n\n')]
    out = []
    for m in re.finditer(r'X\((\w+), (\d+)\)\s*(?:/\*\s*(.*?)\s*\*/)?', block):
        out.append((m.group(1), int(m.group(2)), m.group(3) or ''))
    values = [v for _, v, _ in out]
    if values != list(range(len(values))):
        sys.exit('VFX_LOG_ID_LIST: values are not 0, 1, 2, ... in order (append only): %s' % values)
    return out


def table(header_text):
    rows = ['| id | value | meaning |', '|---|---:|---|']
    for name, value, meaning in ids(header_text):
        rows.append('| `VFX_LOG_ID_%s` | %d | %s |' % (name, value, meaning.replace('|', '\\|')))
    return '\n'.join(rows) + '\n'


def main(argv):
    want = table(HEADER.read_text())
    if len(argv) == 1:
        sys.stdout.write(want)
        return 0
    mode, doc = argv[1], pathlib.Path(argv[2])
    text = doc.read_text()
    a, b = text.index(BEGIN) + len(BEGIN) + 1, text.index(END)
    if mode == '--write':
        doc.write_text(text[:a] + want + text[b:])
        return 0
    if text[a:b] != want:
        sys.stderr.write('%s: the log id table differs from VFX_LOG_ID_LIST in %s; run '
                         'scripts/log-ids-table.py --write %s\n' % (doc, HEADER, doc))
        return 1
    print('%s: %d log ids, as in volfx.h' % (doc, len(ids(HEADER.read_text()))))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
