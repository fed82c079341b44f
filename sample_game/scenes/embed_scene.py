#!/usr/bin/env python3
"""Embeds the default scene JSON as a C string: usage embed_scene.py IN.json OUT.c"""
import sys

src, dst = sys.argv[1], sys.argv[2]
text = open(src, encoding='utf-8').read()
esc = text.replace('\\', '\\\\').replace('"', '\\"').replace('\n', '\\n"\n"')
with open(dst, 'w', encoding='utf-8') as out:
    out.write('/* generated from %s by embed_scene.py */\n' % src.split('/')[-1])
    out.write('const char vfx_default_scene_json[] =\n"%s";\n' % esc)
