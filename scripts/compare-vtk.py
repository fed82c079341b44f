#!/usr/bin/python3
"""compare-vtk.py — the seed-002 renderer side by side with VTK's three unstructured-grid volume
mappers (vtkUnstructuredGridVolumeZSweepMapper, vtkUnstructuredGridVolumeRayCastMapper,
vtkProjectedTetrahedraMapper) on the same mesh, view, resolution and transfer function.

Not part of CI or a README command; needs Debian's VTK, numpy and an X server:
    apt-get install -y python3-vtk9 python3-numpy xvfb xauth
Usage (from the repository root, after `ninja -C build`):
    xvfb-run -a -s '-screen 0 640x480x24' /usr/bin/python3 scripts/compare-vtk.py \
        --mesh ../shared/data/tets/pipe_RCR_init_flow.vtu [--scalar Velocity] [--view across,axis]
        [--size 300] [--reps 5] [--bench build/bench/volfx-bench] [--png-dir DIR]

volfx-bench tetvol --only image gives the camera (eye, centre, up, fovy, near, far), the
transfer function and our images (PFM); this script builds the same camera and transfer function
in VTK, renders each mapper reps + 1 times (the first dropped), and prints one JSON line per
mapper and view: median render time and the image difference against ours.

Transfer function mapping. Ours: extinction tau(u) = tau_lo + (tau_hi - tau_lo) u per world unit
and colour c(u), both linear in u = (s - smin) / (smax - smin). VTK's unstructured-grid mappers
read the scalar opacity a(s) as an extinction per ScalarOpacityUnitDistance d: the ray integrators
(vtkUnstructuredGridHomogeneousRayIntegrator and the linear / pre-integrated ones, used by ZSweep
and RayCast) divide their opacity table by d and take alpha = 1 - exp(-a(s) / d * l) for a length
l, and projected tetrahedra passes a(s) as the attenuation and the thickness divided by d to the
same 1 - exp(-attenuation * thickness). So a(s) = tau(s) d, linear in s like tau (two points
are exact), with d = 1 / tau_hi so that a stays in [0, 1] (PT quantises it to 8 bits). The
mapping before (a = 1 - exp(-tau d) at d = 1) was the opacity of one unit length read as an
extinction: tau 4 became 0.98, and VTK rendered a volume up to 4x thinner than ours. The colour
function gets the two end colours (linear, exact). Shading off, linear interpolation. ZSweep and
RayCast use vtkUnstructuredGridHomogeneousRayIntegrator by default here (the scalar at the
segment's entry, constant along it), --integrator default leaves VTK's choice.

Image difference: on premultiplied RGB (VTK's frame over a black background is premultiplied
colour), 8-bit VTK values / 255 against our float image; RMSE over all pixels and channels (the
background, zero in both, included) and over the pixels our image covers (alpha > 0), and the
max. The 8-bit quantisation alone gives an RMSE of about 0.001.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support

from vtk_view import gl_renderer, offscreen_window


def read_pfm(path):
    with open(path, 'rb') as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), '<f4' if scale < 0 else '>f4')
    ch = 3 if kind == b'PF' else 1
    return data.reshape(h, w, ch)  # row 0 = bottom, as VTK's images


def read_tetgen(base, attr):
    def rows(path):
        out = []
        with open(path) as f:
            for line in f:
                line = line.split('#', 1)[0].split()
                if line:
                    out.append(line)
        return out
    node = rows(base + '.node')
    n, dim, nattr = int(node[0][0]), int(node[0][1]), int(node[0][2])
    arr = np.array(node[1:1 + n], dtype=np.float64)
    first = int(arr[0, 0])
    pts = arr[:, 1:4]
    k = int(attr[4:]) if attr.startswith('attr') and attr[4:] else 0
    if k >= nattr:
        sys.exit('compare-vtk: %s.node has %d attributes, %s asked' % (base, nattr, attr))
    sc = arr[:, 4 + k]
    ele = rows(base + '.ele')
    m = int(ele[0][0])
    tets = np.array(ele[1:1 + m], dtype=np.int64)[:, 1:5] - first
    return pts, sc, tets


def make_grid(pts, sc, tets):
    ug = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    p.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(pts, dtype=np.float32), deep=1))
    ug.SetPoints(p)
    cells = np.hstack([np.full((len(tets), 1), 4, np.int64), tets]).ravel()
    ca = vtk.vtkCellArray()
    ca.SetCells(len(tets), numpy_support.numpy_to_vtkIdTypeArray(cells, deep=1))
    ug.SetCells(vtk.VTK_TETRA, ca)
    s = numpy_support.numpy_to_vtk(np.ascontiguousarray(sc, dtype=np.float32), deep=1)
    s.SetName('scalar')
    ug.GetPointData().SetScalars(s)
    return ug


def load_mesh(path, scalar):
    if path.endswith('.vtu'):
        r = vtk.vtkXMLUnstructuredGridReader()
        r.SetFileName(path)
        r.Update()
        g = r.GetOutput()
        a = numpy_support.vtk_to_numpy(g.GetPointData().GetArray(scalar))
        sc = np.linalg.norm(a, axis=1) if a.ndim == 2 else a  # |Velocity|, as our loader
        pts = numpy_support.vtk_to_numpy(g.GetPoints().GetData())
        conn = numpy_support.vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(-1, 4)
        return make_grid(pts, sc, conn)
    base = path[:-5] if path.endswith('.node') else path[:-4] if path.endswith('.ele') else path
    return make_grid(*read_tetgen(base, scalar))


def unit_distance(tf):
    """VTK's ScalarOpacityUnitDistance for our table: 1 / tau_hi, so a = tau d is in [0, 1]."""
    top = max(tf['tau_lo'], tf['tau_hi'])
    return 1.0 / top if top > 0 else 1.0


def volume_property(tf, mapping='extinction'):
    """VTK's property for our linear transfer function: scalar opacity a = tau d per unit
    distance d (VTK's mappers take a / d as the extinction, see the module docstring);
    mapping 'opacity-d1' is the old mapping a = 1 - exp(-tau) at d = 1, kept to show the
    difference in one run."""
    d = unit_distance(tf) if mapping == 'extinction' else 1.0
    prop = vtk.vtkVolumeProperty()
    op = vtk.vtkPiecewiseFunction()
    col = vtk.vtkColorTransferFunction()
    smin, smax = tf['smin'], tf['smax']
    if mapping == 'extinction':
        op.AddPoint(smin, tf['tau_lo'] * d)
        op.AddPoint(smax, tf['tau_hi'] * d)
    else:
        for i in range(256):
            u = i / 255.0
            op.AddPoint(smin + (smax - smin) * u,
                        1.0 - np.exp(-(tf['tau_lo'] + (tf['tau_hi'] - tf['tau_lo']) * u)))
    col.AddRGBPoint(smin, *tf['color_lo'])
    col.AddRGBPoint(smax, *tf['color_hi'])
    prop.SetScalarOpacity(op)
    prop.SetColor(col)
    prop.SetScalarOpacityUnitDistance(d)
    prop.ShadeOff()
    prop.SetInterpolationTypeToLinear()
    return prop


def make_mapper(name, integrator):
    if name == 'ZSweep':
        m = vtk.vtkUnstructuredGridVolumeZSweepMapper()
    elif name == 'RayCast':
        m = vtk.vtkUnstructuredGridVolumeRayCastMapper()
    else:
        return vtk.vtkProjectedTetrahedraMapper()
    if integrator == 'homogeneous':
        m.SetRayIntegrator(vtk.vtkUnstructuredGridHomogeneousRayIntegrator())
    elif integrator == 'linear':
        m.SetRayIntegrator(vtk.vtkUnstructuredGridLinearRayIntegrator())
    elif integrator == 'preintegration':
        m.SetRayIntegrator(vtk.vtkUnstructuredGridPreIntegration())
    return m


def render(ug, tf, cam, name, integrator, reps, modified, mapping):
    w, h = cam['width'], cam['height']
    mapper = make_mapper(name, integrator)
    mapper.SetInputData(ug)
    vol = vtk.vtkVolume()
    vol.SetMapper(mapper)
    vol.SetProperty(volume_property(tf, mapping))
    ren = vtk.vtkRenderer()
    ren.SetBackground(0, 0, 0)
    ren.AddVolume(vol)
    win = offscreen_window(ren, w, h, cam)
    times, cpus = [], []
    for i in range(reps + 1):
        if modified:
            vol.Modified()  # invalidate what the mapper caches between frames
        t0, c0 = time.perf_counter(), time.process_time()
        win.Render()
        times.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)  # every thread of the process (llvmpipe's too)
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    img = grab.GetOutput()
    arr = numpy_support.vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, 3)
    gl = gl_renderer(win)
    win.Finalize()
    return (arr.astype(np.float64) / 255.0, statistics.median(times[1:]), times[0],
            statistics.median(cpus[1:]), gl)


def ray_march(ug, tf, cam, mask, steps):
    """Independent reference: each masked pixel's ray is sampled at steps midpoints across the
    mesh's bounding box, the scalar found by vtkProbeFilter (linear in the containing tet, float64
    positions), and emission-absorption accumulated in float64 with emission c(u) tau(u), the
    model our renderer and the TF mapping above assume. Pixels outside mask stay 0."""
    w, h = cam['width'], cam['height']
    eye = np.array(cam['eye'])
    f = np.array(cam['center']) - eye
    f /= np.linalg.norm(f)
    sv = np.cross(f, np.array(cam['up']))
    sv /= np.linalg.norm(sv)
    uv = np.cross(sv, f)
    th = np.tan(np.radians(cam['fovy_deg']) / 2)
    ys, xs = np.nonzero(mask)
    dx = ((xs + 0.5) / w * 2 - 1) * th * w / h
    dy = ((ys + 0.5) / h * 2 - 1) * th
    d = f[None, :] + dx[:, None] * sv[None, :] + dy[:, None] * uv[None, :]
    d /= np.linalg.norm(d, axis=1)[:, None]
    b = np.array(ug.GetBounds()).reshape(3, 2)
    # slab intersection of each ray with the bounding box
    with np.errstate(divide='ignore', invalid='ignore'):
        t0 = (b[:, 0][None, :] - eye[None, :]) / d
        t1 = (b[:, 1][None, :] - eye[None, :]) / d
    tn = np.maximum(np.nanmax(np.minimum(t0, t1), axis=1), cam['near'])
    tf_ = np.nanmin(np.maximum(t0, t1), axis=1)
    out = np.zeros((h, w, 3))
    ok = tf_ > tn
    hstep = np.where(ok, (tf_ - tn) / steps, 0.0)
    ts = tn[:, None] + (np.arange(steps)[None, :] + 0.5) * hstep[:, None]
    pts = eye[None, None, :] + ts[:, :, None] * d[:, None, :]
    pd = vtk.vtkPolyData()
    vp = vtk.vtkPoints()
    vp.SetData(numpy_support.numpy_to_vtk(pts.reshape(-1, 3).copy(), deep=1))
    pd.SetPoints(vp)
    probe = vtk.vtkProbeFilter()
    probe.SetInputData(pd)
    probe.SetSourceData(ug)
    loc = vtk.vtkStaticCellLocator()
    probe.SetCellLocatorPrototype(loc)
    probe.Update()
    o = probe.GetOutput()
    sc = numpy_support.vtk_to_numpy(o.GetPointData().GetArray('scalar')).reshape(len(xs), steps)
    valid = numpy_support.vtk_to_numpy(o.GetPointData().GetArray('vtkValidPointMask')).reshape(len(xs), steps) > 0
    u = np.clip((sc - tf['smin']) / (tf['smax'] - tf['smin']), 0, 1)
    tau = np.where(valid, tf['tau_lo'] + (tf['tau_hi'] - tf['tau_lo']) * u, 0.0)
    a = 1 - np.exp(-tau * hstep[:, None])
    T = np.cumprod(np.hstack([np.ones((len(xs), 1)), 1 - a[:, :-1]]), axis=1)
    wgt = T * a
    for k in range(3):
        c = tf['color_lo'][k] + (tf['color_hi'][k] - tf['color_lo'][k]) * u
        out[ys, xs, k] = np.sum(wgt * c, axis=1)
    return out


def write_png(path, rgb):
    h, w, _ = rgb.shape
    a = (np.clip(rgb, 0, 1) * 255 + 0.5).astype(np.uint8)
    im = vtk.vtkImageData()
    im.SetDimensions(w, h, 1)
    im.GetPointData().SetScalars(numpy_support.numpy_to_vtk(a.reshape(-1, 3), deep=1))
    wr = vtk.vtkPNGWriter()
    wr.SetFileName(path)
    wr.SetInputData(im)
    wr.Write()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--mesh', required=True)
    ap.add_argument('--scalar')
    ap.add_argument('--view', default='across,axis')
    ap.add_argument('--size', type=int, default=300)
    ap.add_argument('--reps', type=int, default=5)
    ap.add_argument('--tau', default='4')
    ap.add_argument('--bench', default='build/bench/volfx-bench')
    ap.add_argument('--mappers', default='ZSweep,RayCast,PT')
    ap.add_argument('--integrator', default='homogeneous',
                    choices=['homogeneous', 'linear', 'preintegration', 'default'])
    ap.add_argument('--modified', action='store_true',
                    help='mark the volume modified before each render (VTK rebuilds its caches)')
    ap.add_argument('--mapping', default='extinction', choices=['extinction', 'opacity-d1'],
                    help="transfer function for VTK: a = tau d per unit distance d (right), or "
                         "the old a = 1 - exp(-tau) at d = 1")
    ap.add_argument('--truth-steps', type=int, default=0,
                    help='also ray-march a float64 reference with this many samples per ray')
    ap.add_argument('--png-dir')
    ap.add_argument('--tmp', default='/tmp/compare-vtk')
    a = ap.parse_args()
    os.makedirs(a.tmp, exist_ok=True)
    prefix = os.path.join(a.tmp, 'ours')
    cmd = [a.bench, 'tetvol', '--mesh', a.mesh, '--only', 'image', '--view', a.view,
           '--size', str(a.size), '--reps', str(a.reps), '--tau', a.tau, '--out', prefix]
    if a.scalar:
        cmd += ['--scalar', a.scalar]
    lines = [json.loads(l) for l in subprocess.run(cmd, check=True, capture_output=True,
                                                    text=True).stdout.splitlines()]
    meshline = next(l for l in lines if l['test'] == 'mesh')
    tf = meshline['tf']
    scalar = a.scalar or ('Velocity' if a.mesh.endswith('.vtu') else 'attr0')
    t0 = time.perf_counter()
    ug = load_mesh(a.mesh, scalar)
    load_s = time.perf_counter() - t0
    print(json.dumps({'test': 'vtk_setup', 'mesh': meshline['mesh'], 'tets': ug.GetNumberOfCells(),
                      'vtk': vtk.vtkVersion.GetVTKVersion(), 'integrator': a.integrator, 'modified_each_render': a.modified,
                      'mapping': a.mapping, 'unit_distance': unit_distance(tf) if a.mapping == 'extinction' else 1.0,
                      'load_s': round(load_s, 3)}), flush=True)
    for cam in (l for l in lines if l['test'] == 'image'):
        view = cam['view']
        fast = next(l for l in lines if l['test'] == 'image_fast' and l['view'] == view)
        ours = {'ours_1w_noERT': (read_pfm('%s_%s.rgb.pfm' % (prefix, view)), cam['wall_ms']),
                'ours_2w_ERT0.99': (read_pfm('%s_%s_fast.rgb.pfm' % (prefix, view)), fast['wall_ms'])}
        ours_cpu = {'ours_1w_noERT': cam['cpu_ms'], 'ours_2w_ERT0.99': fast['cpu_ms']}
        alpha = read_pfm('%s_%s.alpha.pfm' % (prefix, view))[:, :, 0]
        cov = alpha > 0
        for k, (img, ms) in ours.items():
            print(json.dumps({'test': 'ours', 'mesh': meshline['mesh'], 'view': view, 'config': k,
                              'ms': ms, 'cpu_ms': ours_cpu[k]}), flush=True)
            if a.png_dir:
                os.makedirs(a.png_dir, exist_ok=True)
                write_png(os.path.join(a.png_dir, '%s_%s_%s.png' % (meshline['mesh'], view, k)), img)
        truth = None
        if a.truth_steps > 0:
            # every pixel any renderer may cover: ours dilated by 2 pixels
            m = cov.copy()
            for _ in range(2):
                m = m | np.roll(m, 1, 0) | np.roll(m, -1, 0) | np.roll(m, 1, 1) | np.roll(m, -1, 1)
            t0 = time.perf_counter()
            truth = ray_march(ug, tf, cam, m, a.truth_steps)
            row = {'test': 'truth', 'mesh': meshline['mesh'], 'view': view, 'steps': a.truth_steps,
                   's': round(time.perf_counter() - t0, 1)}
            for k, (img, ms) in ours.items():
                d = img - truth
                row[k] = {'rmse_rgb': float(np.sqrt(np.mean(d * d))), 'max_rgb': float(np.abs(d).max())}
            print(json.dumps(row), flush=True)
            if a.png_dir:
                write_png(os.path.join(a.png_dir, '%s_%s_truth.png' % (meshline['mesh'], view)), truth)
        vs_truth, vtk_imgs = {}, {}
        for name in a.mappers.split(','):
            img, med, first, cpu, gl = render(ug, tf, cam, name, a.integrator, a.reps, a.modified,
                                              a.mapping)
            vtk_imgs[name] = img
            if a.png_dir:
                write_png(os.path.join(a.png_dir, '%s_%s_%s.png' % (meshline['mesh'], view, name)), img)
            row = {'test': 'vtk', 'mesh': meshline['mesh'], 'view': view, 'mapper': name,
                   'gl_renderer': gl, 'median_ms': round(med * 1e3, 1),
                   'first_ms': round(first * 1e3, 1), 'median_cpu_ms': round(cpu * 1e3, 1)}
            for k, (ours_img, ms) in ours.items():
                d = img - ours_img
                row[k] = {'ours_ms': ms, 'speedup': round(med * 1e3 / ms, 2),
                          'ours_cpu_ms': ours_cpu[k], 'cpu_ratio': round(cpu * 1e3 / ours_cpu[k], 2),
                          'rmse_rgb': float(np.sqrt(np.mean(d * d))),
                          'rmse_rgb_covered': float(np.sqrt(np.mean(d[cov] ** 2))) if cov.any() else 0.0,
                          'max_rgb': float(np.abs(d).max())}
            if truth is not None:
                d = img - truth
                row['vs_truth'] = {'rmse_rgb': float(np.sqrt(np.mean(d * d))),
                                   'max_rgb': float(np.abs(d).max())}
                vs_truth[name] = row['vs_truth']['rmse_rgb']
            print(json.dumps(row), flush=True)
        if len(vs_truth) > 1:
            # the goal: VTK's mappers as close to the reference as to each other (their own
            # spread: the largest RMSE between two of them)
            names = list(vtk_imgs)
            spread = max(float(np.sqrt(np.mean((vtk_imgs[p] - vtk_imgs[q]) ** 2)))
                         for i, p in enumerate(names) for q in names[i + 1:])
            print(json.dumps({'test': 'spread', 'mesh': meshline['mesh'], 'view': view,
                              'vtk_spread_rmse': spread, 'vtk_rmse_vs_truth': vs_truth,
                              'within_spread': all(v <= spread for v in vs_truth.values())}),
                  flush=True)


if __name__ == '__main__':
    main()
