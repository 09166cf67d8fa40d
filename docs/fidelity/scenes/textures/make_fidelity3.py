# Generates the textures of cutout.pbrt and mip.pbrt (run from docs/fidelity/scenes):
# a leaf-shaped alpha mask (grey PFM: 1 inside |v - 1/2| < sin(pi u)/2, with round holes) and a
# 128x128 checker of single texels (grey PFM) for the MIP-mapping picture.
import math, struct

def pfm(path, w, h, f):
    # Grey PFM ("Pf"), rows bottom to top, little-endian (negative scale).
    with open(path, "wb") as out:
        out.write(b"Pf\n%d %d\n-1\n" % (w, h))
        for j in range(h):
            v = (j + 0.5) / h
            out.write(struct.pack("<%df" % w, *[f((i + 0.5) / w, v) for i in range(w)]))

def leaf(u, v):
    inside = abs(v - 0.5) < 0.5 * math.sin(math.pi * u)
    hole = any((u - cu) ** 2 + (v - cv) ** 2 < 0.06 ** 2 for cu, cv in [(0.3, 0.5), (0.5, 0.35), (0.5, 0.65), (0.7, 0.5)])
    return 1.0 if inside and not hole else 0.0

pfm("textures/leaf-alpha.pfm", 128, 128, leaf)
pfm("textures/checker128.pfm", 128, 128, lambda u, v: 0.85 if (int(u * 128) + int(v * 128)) % 2 == 0 else 0.15)
