#!/usr/bin/env python3
"""Mean radiance over the bulb's pixels (and the whole image) of EXR renders of
tests/data/bulb: pixels whose whole footprint sees the glass sphere (centre ray within 0.95 of
its silhouette radius), the same mask for every image. With --ref R.exr, also the mean of the
per-pixel difference image − R over the bulb and its standard error (pixels are independent,
so this error bar is the noise of the difference, not the bulb's spatial variation).
Run with the Mitsuba venv's python (it reads EXR through mitsuba.Bitmap).
Usage: bulb-mean.py [--ref R.exr] IMAGE.exr [...]"""
import sys
import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")
RES, FOV = 128, 30.0
EYE, CENTRE, R = np.array([0.0, -5.0, 1.0]), np.array([0.0, 0.0, 1.0]), 1.0


def mask():
    t = np.tan(np.radians(FOV) / 2)
    px = (np.arange(RES) + 0.5) / RES * 2 - 1
    x, z = np.meshgrid(px * t, -px * t)
    d = np.stack([x, np.ones_like(x), z], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    oc = CENTRE - EYE
    # Distance from the sphere's centre to each pixel's centre ray.
    along = d @ oc
    miss = np.linalg.norm(oc - along[..., None] * d, axis=-1)
    return miss < 0.95 * R


def load(f):
    img = np.array(mi.Bitmap(f).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32))
    return img.mean(-1)


args = sys.argv[1:]
ref = None
if len(args) >= 2 and args[0] == "--ref":
    ref, args = load(args[1]), args[2:]
m = mask()
for f in args:
    y = load(f)
    line = f"{f}: bulb mean {y[m].mean():.4f} ({m.sum()} px), image mean {y.mean():.4f}"
    if ref is not None:
        d = (y - ref)[m]
        line += f", bulb mean − ref {d.mean():+.4f} ± {d.std() / np.sqrt(d.size):.4f}"
    print(line)
