#!/usr/bin/env python3
"""VFX_EXPORT per side and platform: dllexport only in the plugin's own build (VFX_BUILDING_PLUGIN),
dllimport in a Windows host, nothing in a static Windows host (VFX_STATIC) or a host elsewhere.
Runs the C preprocessor on volfx.h with _WIN32 defined by hand (no Windows compiler here), so what
each side's declaration of vfx_plugin_entry expands to is checked, not assumed.
usage: check_export_macro.py INCLUDE_DIR CC [CC ARGS...]"""
import subprocess
import sys


def expand(cc, inc, defines):
    src = '#include <volfx/volfx.h>\nVFX_EXPORT_IS: VFX_EXPORT :END\n'
    out = subprocess.run(cc + ['-E', '-P', '-I', inc] + ['-D' + d for d in defines] + ['-x', 'c', '-'],
                         input=src, capture_output=True, text=True, check=True).stdout
    line = [l for l in out.splitlines() if l.startswith('VFX_EXPORT_IS:')][0]
    return ' '.join(line[len('VFX_EXPORT_IS:'):-len(':END')].split())


def main():
    inc, cc = sys.argv[1], sys.argv[2:]
    cases = [
        (['_WIN32', 'VFX_BUILDING_PLUGIN'], '__declspec(dllexport)'),  # the plugin DLL
        (['_WIN32'], '__declspec(dllimport)'),                         # a host linking the DLL
        (['_WIN32', 'VFX_STATIC'], ''),                                # a host linking it static
        (['VFX_BUILDING_PLUGIN'], '__attribute__((visibility("default")))'),  # the plugin .so
        ([], ''),                                                      # a host elsewhere
    ]
    fail = 0
    for defines, want in cases:
        got = expand(cc, inc, defines)
        ok = got == want
        fail |= not ok
        print('%-32s VFX_EXPORT = %-42s %s' % (' '.join('-D' + d for d in defines) or '(host)', repr(got),
                                               'ok' if ok else 'WANT ' + repr(want)))
    return fail


if __name__ == '__main__':
    sys.exit(main())
