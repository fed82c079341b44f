#!/usr/bin/python3
"""tetvol-cost-table.py — issue 27's cost table in one run: for each mesh and view, one after
the other in the same minutes, (1) the exact integrator against the midpoint rule on 2- and
64-point tables (`volfx-bench tetvol --only tf`, the methods interleaved rep by rep), (2) one
worker without ERT against VTK's RayCast mapper (`scripts/compare-vtk.py --mappers RayCast`,
process CPU), (3) one against two workers (`volfx-bench tetvol --only threads`, wall and total
process CPU, pools interleaved rep by rep), each with the load average read before it.

Usage (repository root, after `ninja -C build`; needs python3-vtk9, numpy and xvfb-run):
    xvfb-run -a /usr/bin/python3 scripts/tetvol-cost-table.py [--reps 3] [--out FILE.jsonl]
        [--meshes dome,pipe,torus] [--view across,axis]
The torus is `scripts/make-tet-mesh.sh build/tetmesh/torus 12000 1` (78,889 tets), made when
missing. Prints the JSON lines (also to --out) and then the Markdown table of docs/tetvol.md.
"""
import argparse
import json
import os
import subprocess
import sys

MESHES = {
    'dome': ('sample_game/scenes/data/dome.vtu', 'field'),
    'pipe': (os.path.join(os.environ.get('VFX_SHARED_DATA', '../shared/data'), 'tets/pipe_RCR_init_flow.vtu'),
             'Velocity'),
    'torus': ('build/tetmesh/torus.node', 'attr0'),
}


def load():
    with open('/proc/loadavg') as f:
        return float(f.read().split()[0])


def jsonl(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return [json.loads(l) for l in out.splitlines() if l.startswith('{')]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--reps', type=int, default=3)
    ap.add_argument('--meshes', default='dome,pipe,torus')
    ap.add_argument('--view', default='across,axis')
    ap.add_argument('--bench', default='build/bench/volfx-bench')
    ap.add_argument('--out')
    a = ap.parse_args()
    if 'torus' in a.meshes and not os.path.exists('build/tetmesh/torus.ele'):
        subprocess.run(['scripts/make-tet-mesh.sh', 'build/tetmesh/torus', '12000', '1'], check=True,
                       capture_output=True)
    out = open(a.out, 'w') if a.out else None
    rows = []

    def emit(d):
        print(json.dumps(d), flush=True)
        if out:
            out.write(json.dumps(d) + '\n')
            out.flush()

    for name in a.meshes.split(','):
        path, scalar = MESHES[name]
        for view in a.view.split(','):
            row = {'mesh': name, 'view': view}
            base = [a.bench, 'tetvol', '--mesh', path, '--scalar', scalar, '--view', view,
                    '--reps', str(a.reps), '--size', '300']
            row['load_tf'] = load()
            for d in jsonl(base + ['--only', 'tf']):
                if d.get('test') == 'tf' and d['points'] in (2, 64) and d['method'] in ('exact', 'midpoint'):
                    row['%s_%d' % (d['method'], d['points'])] = d['cpu_ms']
            row['load_vtk'] = load()
            for d in jsonl(['/usr/bin/python3', 'scripts/compare-vtk.py', '--mesh', path, '--scalar', scalar,
                            '--view', view, '--mappers', 'RayCast', '--reps', str(a.reps), '--bench', a.bench,
                            '--tmp', '/tmp/tetvol-cost-table']):
                if d.get('test') == 'vtk':
                    row['raycast_cpu'] = d['median_cpu_ms']
                    row['ours_cpu'] = d['ours_1w_noERT']['ours_cpu_ms']
                    row['rmse_vs_raycast'] = d['ours_1w_noERT']['rmse_rgb']
            row['load_threads'] = load()
            for d in jsonl(base + ['--only', 'threads']):
                if d.get('test') == 'threads':
                    k = 'ert' if d['ert'] else 'noert'
                    row[k] = {'wall_1': d['wall_ms_1'], 'wall_2': d['wall_ms_2'], 'cpu_1': d['cpu_ms_1'],
                              'cpu_2': d['cpu_ms_2'], 'bound': d['speedup_cpu_bound']}
            row['load_end'] = load()
            emit(row)
            rows.append(row)
    print('\n| mesh, view | exact / midpoint, 2 points | 64 points | ours / RayCast CPU (ms) | ratio '
          '| 2 workers no ERT: wall speed-up, CPU 2/1 | ERT 0.9+share+DLB | load |')
    print('|---|---|---|---|---|---|---|---|')
    for r in rows:
        def t(k):
            c = r[k]
            return '%.2fx, %.2fx' % (c['wall_1'] / c['wall_2'], c['cpu_2'] / c['cpu_1'])
        print('| %s %s | %.1f / %.1f = **%.2f** | %.1f / %.1f = **%.2f** | %.1f / %.1f | **%.2f** | %s | %s | %.1f-%.1f |' % (
            r['mesh'], r['view'], r['exact_2'], r['midpoint_2'], r['exact_2'] / r['midpoint_2'],
            r['exact_64'], r['midpoint_64'], r['exact_64'] / r['midpoint_64'], r['ours_cpu'],
            r['raycast_cpu'], r['ours_cpu'] / r['raycast_cpu'], t('noert'), t('ert'),
            min(r['load_tf'], r['load_end']), max(r['load_tf'], r['load_vtk'], r['load_threads'], r['load_end'])))
    return 0


if __name__ == '__main__':
    sys.exit(main())
