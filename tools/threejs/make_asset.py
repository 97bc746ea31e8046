# The asset of the mip and specular-AA figures: a 2x2 plane (plane.obj) and a tileable 1024^2
# 16-bit height map of twelve waves, periods 6-21 texels (height.png), written into the current folder.
# Deterministic (seeded); pure Python so that it runs where nothing else is installed.
import zlib, struct, math, random
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
def h(x, y):
    s = sum(math.sin(2 * math.pi * (kx * x + ky * y) / N + p) for kx, ky, p in waves)
    return 0.5 + s / (2 * len(waves)) 
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
