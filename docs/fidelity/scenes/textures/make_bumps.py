# Generates the two maps of bumps.pbrt (run from docs/fidelity/scenes): a tangent-space
# normal map of a 4x4 grid of domes (spherical caps) (8-bit PNG, code = (n+1)/2*255, read linearly as pbrt-v4
# does) and a displacement of concentric ripples (grey PFM, linear).
import math, struct, zlib

N = 128

def dome_normal(u, v):
    # A spherical cap of radius R (rim radius r0, rim slope 42 degrees) over a cell's centre:
    # h = sqrt(R^2 - d^2) + const, normal (-dh/du, -dh/dv, 1).
    cu, cv = (u * 4) % 1 - 0.5, (v * 4) % 1 - 0.5
    R, r0, d2 = 0.6, 0.4, cu * cu + cv * cv
    if d2 >= r0 * r0:
        return (0.0, 0.0, 1.0)
    h = math.sqrt(R * R - d2)
    n = (cu / h, cv / h, 1.0)
    l = math.sqrt(sum(c * c for c in n))
    return tuple(c / l for c in n)

def png(path, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", N, N, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))

rows = []
for j in range(N):  # top row first = v = 1
    v = 1 - (j + 0.5) / N
    row = []
    for i in range(N):
        n = dome_normal((i + 0.5) / N, v)
        row += [max(0, min(255, round((c + 1) / 2 * 255))) for c in n]
    rows.append(row)
png("textures/domes-normal.png", rows)

# PFM rows are stored bottom first.
vals = []
for j in range(N):
    v = (j + 0.5) / N
    for i in range(N):
        u = (i + 0.5) / N
        r = math.hypot(u - 0.5, v - 0.5)
        vals.append(0.012 * math.cos(2 * math.pi * 9 * r))
with open("textures/ripples.pfm", "wb") as f:
    f.write(b"Pf\n%d %d\n-1.0\n" % (N, N) + struct.pack("<%df" % len(vals), *vals))
