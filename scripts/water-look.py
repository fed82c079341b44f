#!/usr/bin/python3
"""water-look.py — how much the water changes the image, and what it adds to the beams' light.

Renders a scene at a frame with volfx-game (one run: `--shots F --shot-variants` draws the last
frame again, no time passing, as it is, with the water hidden, the beams off and both; the same
pixels as separate runs with `--hide-water` / `--no-beams`) and reports, over the water's surface (the
pixels where the water's raw distance dump hits, and the 8x8 blocks more than half covered):

  change  the median over the surface's 8x8 blocks of the block-mean colour change the water
          makes (mean over R, G, B of |mean(shown) - mean(hidden)|, 0-1 sRGB). Block means make
          refraction's shifted tile lines cancel: what is left is the water's own colour,
          reflection and light.
  beams   the 95th percentile over the surface's pixels of [the beams' luminance change with the
          water shown] - [the same with it hidden] (Rec. 709 luminance of the sRGB values): the
          light the water adds to the beams (reflected, lit), every image of it drawn at the same
          instant with dt 0 (-again, -nobeams, ...). 0 in a scene without beams.

  --zero-params  the scene with its water's colour, absorption, ior and diffuse block removed:
                 zero-filled water parameters, the plugin's defaults.

usage: scripts/water-look.py [--game build/sample_game/volfx-game] [--plugin PATH] [--size 640x360]
       [--zero-params] [--keep DIR] [--panels N,N,...] [--panel-image OUT.png] SCENE.json FRAME [FRAME...]
--panel-image writes the images of the --panels frames and the measured frames, half size, three
a row, each labelled with its frame (the panels of docs/water-look.md).
Prints one line a frame: scene, frame, change, beams, surface pixels, blocks. Needs numpy, PIL
(Debian: python3-numpy python3-pil; run with /usr/bin/python3).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
from PIL import Image, ImageDraw

BLOCK = 8


def read_pfm(path):
    with open(path, 'rb') as f:
        if f.readline().strip() != b'Pf':
            raise SystemExit(f'water-look: {path}: not a one-channel PFM')
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype='<f4' if scale < 0 else '>f4', count=w * h)
    return data.reshape(h, w)[::-1]  # PFM rows go bottom to top


def load(path):
    return np.asarray(Image.open(path).convert('RGB'), dtype=np.float64) / 255.0


def block_means(img, h, w):
    hb, wb = h // BLOCK, w // BLOCK
    x = img[:hb * BLOCK, :wb * BLOCK]
    return x.reshape(hb, BLOCK, wb, BLOCK, -1).mean(axis=(1, 3))


def luminance(img):
    return img @ np.array([0.2126, 0.7152, 0.0722])


def measure(stem, frame):
    base = f'{stem}-f{frame}'
    dist = read_pfm(base + '-water.pfm')
    hit = np.isfinite(dist) & (dist > 0)
    shown, hidden = load(base + '.png'), load(base + '-hidewater.png')
    h, w = hit.shape
    cover = block_means(hit[..., None].astype(np.float64), h, w)[..., 0]
    blocks = cover > 0.5
    change = np.abs(block_means(shown, h, w) - block_means(hidden, h, w)).mean(axis=2)
    res = {'pixels': int(hit.sum()), 'blocks': int(blocks.sum()),
           'change': float(np.median(change[blocks])) if blocks.any() else 0.0, 'beams': 0.0}
    if os.path.exists(base + '-nobeams.png') and hit.any():
        # the beams' change between frames drawn alike (the variants are drawn again at dt 0); a
        # game without the -again variant compares with the frame as first drawn
        again = load(base + '-again.png') if os.path.exists(base + '-again.png') else shown
        d_shown = luminance(again) - luminance(load(base + '-nobeams.png'))
        d_hidden = luminance(hidden) - luminance(load(base + '-nobeams-hidewater.png'))
        res['beams'] = float(np.percentile((d_shown - d_hidden)[hit], 95))
    return res


def zero_params_scene(scene):
    with open(scene) as f:
        doc = json.load(f)
    water = doc.get('water')
    if not isinstance(water, dict):
        raise SystemExit(f'water-look: {scene}: no "water" object')
    for key in ('color', 'absorption', 'ior', 'diffuse'):
        water.pop(key, None)
    # beside the scene, so its relative paths (meshes, volumes) stay right; a hidden name that
    # .gitignore lists (.water-look-*.json), so `git add -A` never picks it up, and removed after
    # the run
    fd, path = tempfile.mkstemp(prefix='.water-look-zero-', suffix='-' + os.path.basename(scene),
                                dir=os.path.dirname(os.path.abspath(scene)))
    with os.fdopen(fd, 'w') as f:
        json.dump(doc, f, indent=1)
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('scene')
    ap.add_argument('frames', type=int, nargs='+')
    ap.add_argument('--game', default='build/sample_game/volfx-game')
    ap.add_argument('--size', default='640x360')
    ap.add_argument('--plugin', help="volfx-game's --plugin (another build's libvolfx.so.2)")
    ap.add_argument('--zero-params', action='store_true')
    ap.add_argument('--keep', help='write the images here (default: a temporary folder)')
    ap.add_argument('--panels', default='', help='also write the images of these frames (N,N,...) on the way: STEM-fN.png')
    ap.add_argument('--panel-image', help='compose the --panels frames and the measured frames into this PNG')
    a = ap.parse_args()
    out = a.keep or tempfile.mkdtemp(prefix='water-look-')
    os.makedirs(out, exist_ok=True)
    scene = zero_params_scene(a.scene) if a.zero_params else a.scene
    name = ('zero-' if a.zero_params else '') + os.path.splitext(os.path.basename(a.scene))[0]
    try:
        run_frames(a, scene, name, out)
    finally:
        if scene != a.scene:
            os.remove(scene)
    if a.panel_image:
        frames = sorted({int(f) for f in a.panels.split(',') if f} | set(a.frames))
        compose_panels([(f, os.path.join(out, f'{name}-f{f}.png')) for f in frames], a.panel_image)


def compose_panels(shots, path, per_row=3):
    """The shots (frame, png) at half size, per_row a row, each labelled 'frame N'."""
    imgs = [(f, Image.open(p).convert('RGB')) for f, p in shots]
    w, h = imgs[0][1].width // 2, imgs[0][1].height // 2
    rows = (len(imgs) + per_row - 1) // per_row
    sheet = Image.new('RGB', (w * min(per_row, len(imgs)), h * rows), (0, 0, 0))
    draw = ImageDraw.Draw(sheet)
    for k, (f, im) in enumerate(imgs):
        x, y = (k % per_row) * w, (k // per_row) * h
        sheet.paste(im.resize((w, h), Image.LANCZOS), (x, y))
        draw.rectangle([x, y, x + 64, y + 14], fill=(0, 0, 0))
        draw.text((x + 4, y + 2), f'frame {f}', fill=(255, 255, 255))
    sheet.save(path)


def run_frames(a, scene, name, out):
    for frame in a.frames:
        stem = os.path.join(out, name)
        cmd = [a.game, '--headless', '--scene', scene, '--frames', str(frame), '--size', a.size,
               '--png', stem + '.png', '--shots', ','.join(sorted({str(frame)} | {f for f in a.panels.split(',') if f and int(f) < frame}, key=int)),
               '--shot-variants', '--progress', '0'] + (['--plugin', a.plugin] if a.plugin else [])
        run = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if run.returncode:
            sys.stderr.write(run.stdout)
            raise SystemExit(f'water-look: {" ".join(cmd)} failed ({run.returncode})')
        r = measure(stem, frame)
        print(f'{name} frame {frame}: change {r["change"]:.4f} beams {r["beams"]:.4f} '
              f'surface {r["pixels"]} px {r["blocks"]} blocks', flush=True)


if __name__ == '__main__':
    main()
