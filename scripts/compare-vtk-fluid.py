#!/usr/bin/python3
"""compare-vtk-fluid.py — the water effect (method TILE, ours; optionally the paper method and
GRID) against VTK's screen-space fluid renderer vtkOpenGLFluidMapper on the same particles,
camera and image size, CPU time per frame as ratios within one run, interleaved rounds.

Not part of CI; needs Debian's VTK, numpy and an X server (VTK renders through GLX, so under
xvfb-run it uses the same Mesa llvmpipe as our headless EGL context):
    apt-get install -y python3-vtk9 python3-numpy xvfb xauth
Usage (from the repository root, after `ninja -C build`):
    xvfb-run -a -s '-screen 0 1280x720x24' /usr/bin/python3 scripts/compare-vtk-fluid.py \
        [--particles 16384] [--layout pool|layers] [--width 640] [--height 360] [--rounds 3]
        [--frames 3] [--methods tile,grid] [--radius 0.305] [--png-dir DIR] [--bench build/bench/volfx-bench]
A method is a volfx-bench method with optional `+` parts: `+anisotropic` / `+isotropic` (--kernel)
and `+no=BITS` (--disable BITS, VFX_WATER_NO_*), e.g. `tile+anisotropic,tile+anisotropic+no=12288`.

Per round, each of our methods runs as one `volfx-bench metaballs` process (one untimed warm-up
frame, then --frames frames, each uploading the positions again: revision 0), which reports
cpu_ms_per_frame: the process's CPU time (every llvmpipe thread) over the timed frames. Then VTK
renders the same points --frames times after one warm-up render, the points marked modified
before each render (so its buffers are uploaded again too), CPU time from time.process_time()
(every thread of this process, llvmpipe's included). Medians over the rounds; ratios are
ours / VTK. The first round's images are saved (ours: the shaded frame over black; VTK's window).

VTK settings are those of VTK's own TestOpenGLFluidMapper (narrow-range filter, transparent fluid
volume, its colours, refractive index 1.33; the filter's iteration count and radius keep VTK's
defaults, which VTK 9.1's Python wrapping does not expose) with its frustum culler removed (the
fluid mapper draws nothing otherwise, as that test does) and a window without multisampling (on
llvmpipe it also draws nothing into VTK's default 8-sample window). Its particle radius (--radius, default
0.305 = h / 2, about the 0.3 spacing of the layouts) is a choice: VTK splats spheres of that
radius, we ray cast the metaball surface I = sqrt(sum P) - T with h = 0.61.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import vtk
from vtk.util import numpy_support

from vtk_view import gl_renderer, offscreen_window


def run_ours(args, method, tmp, first):
    parts = method.split('+')
    cmd = [args.bench, 'metaballs', '--particles', str(args.particles), '--size', str(args.width),
           '--height', str(args.height), '--layout', args.layout, '--frames', str(args.frames),
           '--method', parts[0], '--points', os.path.join(tmp, 'points.bin')]
    for p in parts[1:]:
        if p in ('anisotropic', 'isotropic'):
            cmd += ['--kernel', p]
        elif p.startswith('no='):
            cmd += ['--disable', p[3:]]
        else:
            raise SystemExit(f'compare-vtk-fluid: unknown method part "{p}" in "{method}"')
    if first and args.png_dir:
        name = method.replace('+', '-').replace('=', '')
        cmd += ['--png', os.path.join(args.png_dir, f'water-vtk-{name}.png')]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads([l for l in out.splitlines() if l.startswith('{')][-1])


def vtk_scene(points, cam, args):
    pts = vtk.vtkPoints()
    pts.SetData(numpy_support.numpy_to_vtk(points, deep=1))
    poly = vtk.vtkPolyData()
    poly.SetPoints(pts)
    m = vtk.vtkOpenGLFluidMapper()
    m.SetInputData(poly)
    m.SetParticleRadius(args.radius)
    m.SetSurfaceFilterMethod(vtk.vtkOpenGLFluidMapper.NarrowRange)
    m.SetDisplayMode(vtk.vtkOpenGLFluidMapper.TransparentFluidVolume)
    m.SetAttenuationColor(0.8, 0.2, 0.15)
    m.SetAttenuationScale(1.0)
    m.SetOpaqueColor(0.0, 0.0, 0.9)
    m.SetParticleColorPower(0.1)
    m.SetParticleColorScale(0.57)
    m.SetAdditionalReflection(0.0)
    m.SetRefractiveIndex(1.33)
    m.SetRefractionScale(0.07)
    vol = vtk.vtkVolume()
    vol.SetMapper(m)
    ren = vtk.vtkRenderer()
    ren.SetBackground(0.35, 0.4, 0.5)  # the host colour volfx-bench metaballs clears to
    ren.AddVolume(vol)
    ren.GetCullers().RemoveAllItems()  # the fluid mapper draws nothing with the frustum culler
    # no MSAA: with VTK's default 8x window the fluid mapper's result never shows
    return offscreen_window(ren, args.width, args.height, cam, multisamples=0), poly


def run_vtk(win, poly, frames):
    poly.Modified()
    win.Render()  # warm-up: shader compilation
    cpus, walls = [], []
    for _ in range(frames):
        poly.Modified()
        t0, c0 = time.perf_counter(), time.process_time()
        win.Render()
        walls.append((time.perf_counter() - t0) * 1e3)
        cpus.append((time.process_time() - c0) * 1e3)
    return statistics.median(cpus), statistics.median(walls)


def save_vtk_png(win, path):
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    wr = vtk.vtkPNGWriter()
    wr.SetFileName(path)
    wr.SetInputConnection(grab.GetOutputPort())
    wr.Write()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--particles', type=int, default=16384)
    ap.add_argument('--layout', default='pool', choices=['pool', 'layers'])
    ap.add_argument('--width', type=int, default=640)
    ap.add_argument('--height', type=int, default=360)
    ap.add_argument('--rounds', type=int, default=3)
    ap.add_argument('--frames', type=int, default=3)
    ap.add_argument('--methods', default='tile,grid')
    ap.add_argument('--radius', type=float, default=0.305)
    ap.add_argument('--png-dir')
    ap.add_argument('--bench', default='build/bench/volfx-bench')
    args = ap.parse_args()
    methods = args.methods.split(',')
    if args.png_dir:
        os.makedirs(args.png_dir, exist_ok=True)
    cpu = {m: [] for m in methods + ['vtk']}
    wall = {m: [] for m in methods + ['vtk']}
    renderer = None
    with tempfile.TemporaryDirectory() as tmp:
        win = poly = None
        for r in range(args.rounds):
            for m in methods:
                j = run_ours(args, m, tmp, r == 0)
                cpu[m].append(j['cpu_ms_per_frame'])
                wall[m].append(j['frame_ms']['p50'])
                renderer = j['gl_renderer']
                if win is None:
                    pts = np.fromfile(os.path.join(tmp, 'points.bin'), dtype=np.float32).reshape(-1, 3)
                    win, poly = vtk_scene(pts, j['camera'], args)
                print(json.dumps({'round': r, 'method': m, 'cpu_ms_per_frame': j['cpu_ms_per_frame'],
                                  'wall_ms_p50': j['frame_ms']['p50'],
                                  'samples': j['counters'].get('water.samples'),
                                  'undecided': j['counters'].get('water.pixels_undecided')}), flush=True)
            c, w = run_vtk(win, poly, args.frames)
            cpu['vtk'].append(c)
            wall['vtk'].append(w)
            print(json.dumps({'round': r, 'method': 'vtk', 'cpu_ms_per_frame': c, 'wall_ms_p50': w}), flush=True)
            if r == 0 and args.png_dir:
                save_vtk_png(win, os.path.join(args.png_dir, 'water-vtk-vtkfluid.png'))
    vtk_gl = gl_renderer(win) if win else '?'
    print(f'\n{args.particles} particles ({args.layout}), {args.width}x{args.height}, {args.rounds} rounds of '
          f'{args.frames} frames; ours: {renderer}; VTK {vtk.vtkVersion.GetVTKVersion()}: {vtk_gl}; '
          f'{os.cpu_count()} cores\n')
    print('| method | CPU ms / frame (median of rounds) | wall ms / frame | CPU / VTK |')
    print('|---|---|---|---|')
    v = statistics.median(cpu['vtk'])
    for m in methods + ['vtk']:
        c = statistics.median(cpu[m])
        name = 'vtkOpenGLFluidMapper' if m == 'vtk' else m
        print(f'| {name} | {c:.0f} | {statistics.median(wall[m]):.0f} | {c / v:.2f} |')


if __name__ == '__main__':
    sys.exit(main())
