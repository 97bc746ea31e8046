# The asset of the mip and specular-AA figures: a 2x2 plane (plane.obj) and a tileable 1024^2
# 16-bit height map (height.png), written into the current folder:
#   python3 make_asset.py          twelve waves, periods 6-21 texels (a regular pattern)
#   python3 make_asset.py noise    random bumps: 256 waves of random direction and phase, periods
#                                  6-128 texels spread as a white noise's modes are, height
#                                  amplitude proportional to the period (nearly Gaussian slopes;
#                                  needs numpy)
# Deterministic (seeded); the waves in pure Python so that they run where nothing else is installed.
import zlib, struct, math, random, sys
def png16(path, w, h, f):
    raw = bytearray()
    for y in range(h):
        raw.append(0)
        for x in range(w):
            v = max(0, min(65535, int(round(f(x, y) * 65535))))
            raw += struct.pack('>H', v)
    def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 16, 0, 0, 0, 0)) + chunk(b'IDAT', zlib.compress(bytes(raw), 6)) + chunk(b'IEND', b''))
N = 1024
random.seed(7)
waves = []
for period in (6, 9, 13, 21):
    for _ in range(3):
        a = random.uniform(0, 2 * math.pi)
        # periods dividing N keep the map tileable
        k = round(N / period)
        kx, ky = round(k * math.cos(a)), round(k * math.sin(a))
        waves.append((kx, ky, random.uniform(0, 2 * math.pi)))
amps = [1.0] * len(waves)
if sys.argv[1:] == ['noise']:
    waves, amps = [], []
    kmin, kmax = N / 128, N / 6
    for _ in range(256):
        k = math.sqrt(kmin * kmin + random.random() * (kmax * kmax - kmin * kmin))
        a = random.uniform(0, 2 * math.pi)
        kx, ky = round(k * math.cos(a)), round(k * math.sin(a))
        waves.append((kx, ky, random.uniform(0, 2 * math.pi)))
        amps.append(1 / max(1.0, math.hypot(kx, ky)))
def raw(x, y):
    return sum(c * math.sin(2 * math.pi * (kx * x + ky * y) / N + p) for c, (kx, ky, p) in zip(amps, waves))
if sys.argv[1:] == ['noise']:
    # Rescaled to [0, 1] over the map. 256 waves a texel is numpy's work (pure Python: minutes).
    import numpy as np
    yy, xx = np.mgrid[0:N, 0:N].astype(np.float64)
    vals = sum(c * np.sin(2 * np.pi * (kx * xx + ky * yy) / N + p) for c, (kx, ky, p) in zip(amps, waves))
    lo, hi = vals.min(), vals.max()
    h = lambda x, y: (vals[y, x] - lo) / (hi - lo)
else:
    h = lambda x, y: 0.5 + raw(x, y) / (2 * len(waves))
png16('height.png', N, N, h)
open('plane.obj', 'w').write('''mtllib plane.mtl
v -1 0 1
v 1 0 1
v 1 0 -1
v -1 0 -1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 1 0
usemtl bumpy
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
''')
open('plane.mtl', 'w').write('newmtl bumpy\nKd 0.5 0.5 0.5\n')
