#!/usr/bin/env python3
# coloured-globe.py RINGS SEGMENTS OUT.gltf [all|uv|none]: the coloured lat-long sphere of
# tests/textured_fixture.h's coloured_sphere as glTF (OUT.gltf + OUT.bin): POSITION, TEXCOORD_0,
# TEXCOORD_1 (0.25 + u / 2, v / 2), COLOR_0 (north red with green = latitude, south blue at alpha
# 0.5; the equator doubled, a colour seam), 2 x RINGS x SEGMENTS triangles. "uv" writes
# TEXCOORD_0 only, "none" positions only. 500 1000 gives a 1M-triangle coloured globe.
import sys, math, struct, json, array
rings, segs, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
mode = sys.argv[4] if len(sys.argv) > 4 else 'all'
pos = array.array('f'); uv = array.array('f')
for r in range(rings + 1):
    th = math.pi * (0.02 + 0.96 * r / rings)
    for s in range(segs + 1):
        ph = 0.0 if s == segs else 2 * math.pi * s / segs
        pos.extend((math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)))
        uv.extend((s / segs, r / rings))
idx = array.array('I')
for r in range(rings):
    for s in range(segs):
        a = r * (segs + 1) + s; b = a + 1; c = a + segs + 1; d = c + 1
        idx.extend((a, c, b, b, c, d))
row = segs + 1; eq = (rings // 2) * row; copies = len(pos) // 3
if mode == 'all':
    for v in range(eq, eq + row):
        pos.extend(pos[3*v:3*v+3]); uv.extend(uv[2*v:2*v+2])
    north = (rings // 2) * segs * 2
    for i in range(3 * north, len(idx)):
        v = idx[i]
        if eq <= v < eq + row: idx[i] = copies + (v - eq)
nv = len(pos) // 3
col = array.array('f'); uv1 = array.array('f')
for v in range(nv):
    vv = uv[2*v+1]
    south = v >= copies or v > eq + row - 1
    col.extend((0, 0, 1, 0.5) if south else (1, vv, 0, 1))
    uv1.extend((0.25 + uv[2*v] / 2, vv / 2))
bufs = [('POSITION', pos, 'VEC3'), ('indices', idx, 'SCALAR')]
if mode in ('all', 'uv'): bufs.append(('TEXCOORD_0', uv, 'VEC2'))
if mode == 'all': bufs += [('TEXCOORD_1', uv1, 'VEC2'), ('COLOR_0', col, 'VEC4')]
blob = b''; views = []; accs = []; attrs = {}
for name, a, t in bufs:
    data = a.tobytes(); off = len(blob); blob += data
    views.append({'buffer': 0, 'byteOffset': off, 'byteLength': len(data)})
    n = len(a) // {'VEC3': 3, 'VEC2': 2, 'VEC4': 4, 'SCALAR': 1}[t]
    acc = {'bufferView': len(views) - 1, 'componentType': 5125 if name == 'indices' else 5126, 'count': n, 'type': t}
    if name == 'POSITION':
        acc['min'] = [min(a[k::3]) for k in range(3)]; acc['max'] = [max(a[k::3]) for k in range(3)]
    accs.append(acc)
    if name != 'indices': attrs[name] = len(accs) - 1
binname = out.rsplit('/', 1)[-1].replace('.gltf', '.bin')
open(out.replace('.gltf', '.bin'), 'wb').write(blob)
g = {'asset': {'version': '2.0'}, 'buffers': [{'uri': binname, 'byteLength': len(blob)}], 'bufferViews': views,
     'accessors': accs, 'meshes': [{'primitives': [{'attributes': attrs, 'indices': 1}]}], 'nodes': [{'mesh': 0}],
     'scenes': [{'nodes': [0]}], 'scene': 0}
json.dump(g, open(out, 'w'))
print(nv, 'vertices', len(idx) // 3, 'triangles')
