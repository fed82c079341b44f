#!/usr/bin/env python3
"""Embeds the default scene JSON in the binary: usage embed_scene.py IN.json OUT.c

Defines
  const char game_default_scene_json[];          NUL-terminated text of IN.json
  const unsigned long game_default_scene_json_len; its length in bytes (without the NUL)
The JSON is checked here so a broken default scene fails the build, not the game."""
import json
import sys

src, dst = sys.argv[1], sys.argv[2]
data = open(src, 'rb').read()
try:
    json.loads(data.decode('utf-8'))
except (UnicodeDecodeError, ValueError) as e:
    sys.exit('%s: not valid UTF-8 JSON: %s' % (src, e))

def c_line(chunk):
    # octal escapes for anything outside printable ASCII and for the characters C treats specially
    # (quote, backslash, '?' against trigraphs); three digits so a following digit is never absorbed
    out = []
    for b in chunk:
        ch = chr(b)
        if 32 <= b < 127 and ch not in '"\\?':
            out.append(ch)
        else:
            out.append('\\%03o' % b)
    return '"' + ''.join(out) + '"'

with open(dst, 'w', encoding='ascii') as out:
    out.write('/* generated from %s by embed_scene.py; do not edit */\n' % src.replace('\\', '/').split('/')[-1])
    out.write('const char game_default_scene_json[] =\n')
    lines = data.split(b'\n')
    for i, line in enumerate(lines):
        if i + 1 < len(lines):
            line += b'\n'
        if line:
            out.write('    %s\n' % c_line(line))
    if not data:
        out.write('    ""\n')
    out.write('    ;\n')
    out.write('const unsigned long game_default_scene_json_len = %d;\n' % len(data))
