#!/usr/bin/env bash
# The command-line baker on tiny OBJ files this script writes itself: a good quad bakes and
# writes its outputs; every bad input gets one line on stderr and a non-zero exit.
# usage: test_bake_cli.sh HEMILIGHT_BAKE TMPDIR
set -uo pipefail
bake=$1
dir=$2/bake_cli
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || exit 1
fails=0

# A 1 x 1 floor quad facing up (+y) with vt coordinates covering the unit square.
cat > quad.obj <<'OBJ'
v 0 0 0
v 1 0 0
v 1 0 1
v 0 0 1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 1 0
f 1/1/1 4/4/1 3/3/1 2/2/1
OBJ
sed 's/^vt 1 1$/vt 1.5 1/' quad.obj > outside.obj
grep -v '^vt' quad.obj | sed 's#/[0-9]*/#//#g' > nouv.obj
sed 's/^vt 1 1$/vt 0 0/' quad.obj > flat.obj

expect_ok() {
  if ! "$bake" "$@" --quiet > ok.log 2>&1; then echo "FAIL: $* should succeed:"; cat ok.log; fails=$((fails + 1)); fi
}
expect_fail() {  # expect_fail WORDS... -- ARGS...
  local words=() ; while [ "$1" != "--" ]; do words+=("$1"); shift; done; shift
  "$bake" --quiet "$@" > out.log 2> err.log
  local rc=$?
  local lines; lines=$(grep -c . err.log)
  if [ $rc -eq 0 ] || [ "$lines" -ne 1 ]; then
    echo "FAIL: $* gave exit $rc and $lines stderr lines:"; cat err.log; fails=$((fails + 1)); return
  fi
  for w in "${words[@]}"; do
    grep -q -- "$w" err.log || { echo "FAIL: $*: '$w' not in: $(cat err.log)"; fails=$((fails + 1)); }
  done
}

# The sky (1, 1, 1) over an unoccluded up-facing quad gives E = pi everywhere.
expect_ok quad.obj --lightmap-uv 0 --size 16 --resolution 16 --bounces 1 --out res
for f in res/quad_irradiance.exr res/quad_mask.exr res/quad_irradiance.png; do
  [ -s "$f" ] || { echo "FAIL: $f not written"; fails=$((fails + 1)); }
done
grep -q "256 sampled" ok.log || { echo "FAIL: expected 256 sampled texels:"; cat ok.log; fails=$((fails + 1)); }
# (through a file: grep -q stops reading at the first match, and a pipe would end --help's
# output with SIGPIPE, which pipefail counts as a failure)
"$bake" --help > help.txt && grep -q "usage: hemilight_bake" help.txt || { echo "FAIL: --help"; fails=$((fails + 1)); }

expect_ok quad.obj --lightmap-uv 0 --size 8 --resolution 16 --bounces 1 --directional both --out dir
for f in dir/quad_sh_l1_0.exr dir/quad_sh_l1_3.exr dir/quad_hl2_0.exr dir/quad_hl2_2.exr; do
  [ -s "$f" ] || { echo "FAIL: $f not written"; fails=$((fails + 1)); }
done
expect_ok quad.obj --lightmap-uv 0 --size 8 --resolution 16 --bounces 1 --directional hl2 --out hl2only
[ -e hl2only/quad_sh_l1_0.exr ] && { echo "FAIL: --directional hl2 wrote SH maps"; fails=$((fails + 1)); }
[ -s hl2only/quad_hl2_1.exr ] || { echo "FAIL: --directional hl2 wrote no HL2 maps"; fails=$((fails + 1)); }

# Lights: --sun and --point add lights, --shadow-mask writes their visibility.
expect_ok quad.obj --lightmap-uv 0 --size 8 --resolution 16 --bounces 1 --sky 0,0,0 --sun 0.3,-1,0.2,5 --point 0.5,1,0.5,2,0.05 --shadow-mask --out lit
grep -q "2 lights: direct light" ok.log || { echo "FAIL: expected 2 lights:"; cat ok.log; fails=$((fails + 1)); }
[ -s lit/quad_shadow_mask.exr ] || { echo "FAIL: lit/quad_shadow_mask.exr not written"; fails=$((fails + 1)); }

# Ambient occlusion: --ao D writes NAME_ao.exr next to the irradiance; the quad under the open sky
# sees nothing within D: exactly 1 at every texel. Without --ao no AO file.
expect_ok quad.obj --lightmap-uv 0 --size 8 --resolution 16 --bounces 2 --ao 0.5 --out ao
[ -s ao/quad_ao.exr ] || { echo "FAIL: ao/quad_ao.exr not written"; fails=$((fails + 1)); }
grep -q "ambient occlusion within 0.5: mean 1.000, lowest 1.000 over the sampled texels" ok.log ||
  { echo "FAIL: expected AO 1 everywhere:"; cat ok.log; fails=$((fails + 1)); }
grep -q "quad_{irradiance.exr,mask.exr,ao.exr,irradiance.png}" ok.log || { echo "FAIL: ao.exr not in the written files:"; cat ok.log; fails=$((fails + 1)); }
[ -e res/quad_ao.exr ] && { echo "FAIL: res/quad_ao.exr written without --ao"; fails=$((fails + 1)); }
expect_fail "--ao 0" "(0" -- quad.obj --lightmap-uv 0 --ao 0
expect_fail "--ao -1" -- quad.obj --lightmap-uv 0 --ao -1
expect_fail "--ao nan" -- quad.obj --lightmap-uv 0 --ao nan
expect_fail "--ao needs a value" -- quad.obj --lightmap-uv 0 --ao

# Probes: a grid and a file of points; the JSON's fields, and a probe 0.5 above the floor's centre
# under the uniform sky (radiance 1): c_0 lies between Y00 (4 pi - Omega) (a black floor) and
# Y00 4 pi (a white one), Omega = 4 asin(1/2) = 2 pi / 3 the floor's solid angle from there.
printf '# x y z\n0.5 0.5 0.5\n\n0.2 1 0.8\n' > probes.txt
expect_ok quad.obj --lightmap-uv 0 --size 8 --resolution 16 --bounces 2 --probes probes.txt --out probes
expect_ok quad.obj --lightmap-uv 0 --size 8 --resolution 16 --bounces 1 --probes 2x1x3 --out grid
python3 - <<'PY' || fails=$((fails + 1))
import json, math
d = json.load(open('probes/quad_probes.json'))
assert d['format'] == 'hemilight_probes' and d['version'] == 1 and d['grid'] is None and d['resolution'] == 16, d
assert len(d['probes']) == 2 and d['probes'][0]['position'] == [0.5, 0.5, 0.5], d['probes'][0]
y00 = 0.5 / math.sqrt(math.pi)
for p in d['probes']:
    assert len(p['sh9_rgb']) == 27 and p['backface_fraction'] == 0.0, p
c0 = d['probes'][0]['sh9_rgb'][0]
assert y00 * (4 * math.pi - 2 * math.pi / 3) - 1e-4 <= c0 <= y00 * 4 * math.pi + 1e-4, c0
g = json.load(open('grid/quad_probes.json'))
assert g['grid'] == [2, 1, 3] and len(g['probes']) == 6 and g['bounds']['max'] == [1, 0, 1], g['grid']
assert all(abs(a - b) < 1e-6 for a, b in zip(g['probes'][1]['position'], [0.75, 0, 1 / 6])), g['probes'][1]['position']
PY
expect_fail "--probes 0x1x1" "grid at most" -- quad.obj --lightmap-uv 0 --probes 0x1x1
expect_fail "--probes nofile.txt" "cannot be read" -- quad.obj --lightmap-uv 0 --probes nofile.txt
printf '0.5 0.5\n' > short.txt
expect_fail "short.txt: line 1" -- quad.obj --lightmap-uv 0 --probes short.txt
expect_fail "--indirect-only" -- quad.obj --lightmap-uv 0 --probes 1x1x1 --indirect-only

# A glTF 2.0 quad (the same floor) with a KHR_lights_punctual point light on a node at
# (0.5, 1, 0.5): the model's own light is baked.
python3 - <<'PY'
import base64, json, struct
data = struct.pack('<12f', 0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0) + struct.pack('<8f', 0, 0, 0, 1, 1, 1, 1, 0) + \
       struct.pack('<6H', 0, 1, 2, 0, 2, 3)
gltf = {
    "asset": {"version": "2.0"}, "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1, 1, 1], "intensity": 5}]}},
    "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0}, {"name": "lamp", "translation": [0.5, 1, 0.5], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2}]}],
    "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                    {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
}
open('lamp.gltf', 'w').write(json.dumps(gltf))
PY
expect_ok lamp.gltf --lightmap-uv 0 --size 8 --resolution 16 --bounces 1 --sky 0,0,0 --out gltf
grep -q "1 light from the model" ok.log || { echo "FAIL: the glTF's light was not read:"; cat ok.log; fails=$((fails + 1)); }

# Opacity: a glTF floor (lightmap u in [0, 0.5]) under an alpha-tested card (glTF MASK whose
# base colour texture leaves.png has an alpha channel; lightmap u in [0.5, 1]): one line names the
# see-through material, the bake takes the alpha texture and its texcoords (the scene refuses a
# texture without them), --ignore-opacity bakes it opaque, a missing texture is one error naming
# the material and the file, and the lightmap_uvs.glb written with generated UVs keeps the mode.
python3 - <<'PY'
import base64, json, struct, zlib
def png_rgba(w, h, rgba):
    raw = b''.join(b'\x00' + bytes(rgba[4 * w * y:4 * w * (y + 1)]) for y in range(h))
    chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    return b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 6, 0, 0, 0)) + \
           chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b'')
open('leaves.png', 'wb').write(png_rgba(4, 4, [v for y in range(4) for x in range(4) for v in (40, 160, 40, 255 if x < 2 else 0)]))
quad = struct.pack('<12f', 0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0)
data = quad + struct.pack('<8f', 0, 0, 0, 1, 1, 1, 1, 0) + struct.pack('<8f', 0, 0, 0, 1, 0.5, 1, 0.5, 0) + \
       struct.pack('<8f', 0.5, 0, 0.5, 1, 1, 1, 1, 0) + struct.pack('<6H', 0, 1, 2, 0, 2, 3)
views = [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in ((0, 48), (48, 32), (80, 32), (112, 32), (144, 12))]
gltf = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"name": "floor", "mesh": 0}, {"name": "card", "mesh": 1, "translation": [0, 0.5, 0]}],
    "meshes": [{"name": "Floor", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}, "indices": 4, "material": 0}]},
               {"name": "Card", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 3}, "indices": 4, "material": 1}]}],
    "materials": [{"name": "Ground"},
                  {"name": "Leaves", "alphaMode": "MASK", "doubleSided": True, "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    "textures": [{"source": 0}], "images": [{"uri": "leaves.png"}],
    "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    "bufferViews": views,
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]}] +
                 [{"bufferView": k, "componentType": 5126, "count": 4, "type": "VEC2"} for k in (1, 2, 3)] +
                 [{"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}],
}
open('card.gltf', 'w').write(json.dumps(gltf))
PY
expect_ok card.gltf --size 16 --resolution 16 --bounces 1 --sun 0,-1,0,2 --out card
grep -q "card: 1 of [0-9]* materials lets light through: 'Leaves' alpha-tested (MASK, cutoff 0.5, alpha texture '.*leaves.png' 4 x 4)" ok.log ||
  { echo "FAIL: no opacity line:"; cat ok.log; fails=$((fails + 1)); }
expect_ok card.gltf --size 16 --resolution 16 --bounces 1 --ignore-opacity --out card_opaque
grep -q "card: 1 see-through material baked opaque (opacity ignored)" ok.log || { echo "FAIL: --ignore-opacity:"; cat ok.log; fails=$((fails + 1)); }
grep -q "lets light through" ok.log && { echo "FAIL: --ignore-opacity still lets light through:"; cat ok.log; fails=$((fails + 1)); }
expect_ok card.gltf --size 16 --resolution 16 --bounces 1 --generate-uvs --out card_uvs
if ! "$bake" card_uvs/card_lightmap_uvs.glb --size 16 --resolution 16 --bounces 1 --quiet --out card_again > card_again.log 2>&1 ||
   ! grep -q "'Leaves' alpha-tested (MASK, cutoff 0.5, alpha texture" card_again.log; then
  echo "FAIL: the written glb lost the card's alpha mode or texture:"; cat card_again.log; fails=$((fails + 1))
fi
mv leaves.png leaves_moved.png
expect_fail "material 1 ('Leaves')" "leaves.png' cannot be read" -- card.gltf --size 16
mv leaves_moved.png leaves.png

expect_fail "--sun 1,2" "DX,DY,DZ,E" -- quad.obj --lightmap-uv 0 --sun 1,2
expect_fail "--point 0,0,0,x" "X,Y,Z,I" -- quad.obj --lightmap-uv 0 --point 0,0,0,x
expect_fail "lights\[0\].direction is zero" -- quad.obj --lightmap-uv 0 --sun 0,0,0,1
expect_fail "missing.obj" "no such file" -- missing.obj
expect_fail "--directional sideways" "sh, hl2 or both" -- quad.obj --lightmap-uv 0 --directional sideways
expect_fail "nosky.exr" "no such file" -- quad.obj --lightmap-uv 0 --environment nosky.exr
printf 'not an exr' > bad.exr
expect_fail "bad.exr" -- quad.obj --lightmap-uv 0 --environment bad.exr
# A model without lightmap UVs gets them (one line says so) and is written back with them.
expect_ok nouv.obj --lightmap-uv 0 --size 16 --resolution 16 --bounces 1 --out gen
grep -q "generating lightmap UVs for the whole model" ok.log || { echo "FAIL: no generation message:"; cat ok.log; fails=$((fails + 1)); }
[ -s gen/nouv_lightmap_uvs.glb ] || { echo "FAIL: gen/nouv_lightmap_uvs.glb not written"; fails=$((fails + 1)); }
expect_fail "outside \[0, 1\] by more than 0.001" -- outside.obj --lightmap-uv 0
# UVs without area: an error with --strict; without it the triangles cover nothing (and here
# nothing else does).
expect_fail "zero area in lightmap UV space" "--strict" -- flat.obj --lightmap-uv 0 --strict
expect_fail "no texel is covered" -- flat.obj --lightmap-uv 0
# Previews: --preview renders the baked model (default camera, or eye,target,fov); a bad camera
# is a usage error.
expect_ok quad.obj --lightmap-uv 0 --size 8 --resolution 16 --bounces 1 --preview --out pv
[ -s pv/quad_preview.png ] || { echo "FAIL: pv/quad_preview.png not written"; fails=$((fails + 1)); }
expect_ok quad.obj --lightmap-uv 0 --size 8 --resolution 16 --bounces 1 --preview 0.5,2,0.5,0.5,0,0.5,50 --out pv2
grep -q "preview from (0.5, 2, 0.5) towards (0.5, 0, 0.5), 50 degrees" ok.log || { echo "FAIL: camera not used:"; cat ok.log; fails=$((fails + 1)); }
[ -e pv2/quad_irradiance.png ] && [ -s pv2/quad_preview.png ] || { echo "FAIL: pv2 outputs"; fails=$((fails + 1)); }
expect_fail "--preview 1,1,1,1,1,1" "EX,EY,EZ,TX,TY,TZ" -- quad.obj --lightmap-uv 0 --preview 1,1,1,1,1,1
expect_fail "--preview 0,1,0,0,0,0,150" -- quad.obj --lightmap-uv 0 --preview 0,1,0,0,0,0,150
# Lightmap UVs come from UV channel 1 by default: an OBJ has only channel 0, so they are made.
expect_ok quad.obj --size 16 --resolution 16 --bounces 1 --out ch1
grep -q "1 of 1 meshes have no lightmap UVs (UV channel 1)" ok.log || { echo "FAIL: channel 1 not reported missing:"; cat ok.log; fails=$((fails + 1)); }

# A level as real exports come, with no other flag than the model: an OBJ without UVs, every
# triangle with its own vertices, moved by a transform, with collinear slivers (midpoints exact
# before the transform), a zero-length edge and a point; then the glTF it writes, baked again with
# the UVs it holds (TEXCOORD_1): the same texels.
python3 - <<'PY'
import math
c, s = math.cos(0.6), math.sin(0.6)
V, F = [], []
def place(p):
    x, y, z = p
    return (c * x + s * z + 37.25, y + 2.5, -s * x + c * z - 11.75)
def tri(a, b, d):
    for p in (a, b, d): V.append(place(p))
    F.append((len(V) - 2, len(V) - 1, len(V)))
def box(lo, hi, inward):
    p = [(lo[0], lo[1], lo[2]), (hi[0], lo[1], lo[2]), (hi[0], hi[1], lo[2]), (lo[0], hi[1], lo[2]),
         (lo[0], lo[1], hi[2]), (hi[0], lo[1], hi[2]), (hi[0], hi[1], hi[2]), (lo[0], hi[1], hi[2])]
    for f in [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (0, 4, 7, 3), (1, 2, 6, 5)]:
        q = [p[i] for i in (reversed(f) if inward else f)]
        tri(q[0], q[1], q[2]); tri(q[0], q[2], q[3])
box((0, 0, 0), (4, 3, 5), False)         # a building under the sky
box((5, 0, 0), (6, 1, 1), False)         # a crate beside it
box((-2, -0.2, -2), (9, 0, 7), False)    # the ground slab
for k in range(4):
    tri((k, 0, 0), (k + 0.5, 0, 0), (k + 1, 0, 0))   # collinear slivers along the building's foot
tri((1, 0, 1), (1, 0, 1), (2, 0, 1))                # a zero-length edge
tri((3, 1, 3), (3, 1, 3), (3, 1, 3))                # a point
with open('level.obj', 'w') as f:
    for v in V: f.write('v %.9g %.9g %.9g\n' % v)
    for t in F: f.write('f %d %d %d\n' % t)
PY
if ! "$bake" level.obj > level.log 2>&1; then echo "FAIL: hemilight_bake level.obj:"; cat level.log; fails=$((fails + 1)); fi
for w in "generating lightmap UVs for the whole model" "skipped 6 degenerate triangles" "wrote out/level_lightmap_uvs.glb"; do
  grep -q "$w" level.log || { echo "FAIL: '$w' not in:"; cat level.log; fails=$((fails + 1)); }
done
for f in out/level_irradiance.exr out/level_mask.exr out/level_lightmap_uvs.glb; do
  [ -s "$f" ] || { echo "FAIL: $f not written"; fails=$((fails + 1)); }
done
sampled=$(grep -o "texels: [0-9]* sampled of [0-9]* covered" level.log)
if ! "$bake" out/level_lightmap_uvs.glb --out again > again.log 2>&1; then echo "FAIL: rebaking the written glb:"; cat again.log; fails=$((fails + 1)); fi
grep -q "generating" again.log && { echo "FAIL: the written glb's UVs were not used:"; cat again.log; fails=$((fails + 1)); }
grep -q "$sampled" again.log || { echo "FAIL: '$sampled' not in:"; cat again.log; fails=$((fails + 1)); }
# UVs a hair outside [0, 1] (a glTF with TEXCOORD_1 at -0.00048) are clamped with a warning.
python3 - <<'PY'
import base64, json, struct
data = struct.pack('<12f', 0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0) + struct.pack('<8f', -0.00048, 0, -0.00048, 1, 1, 1, 1, 0) + \
       struct.pack('<6H', 0, 1, 2, 0, 2, 3)
gltf = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 1}, "indices": 2}]}],
    "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                    {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
}
open('margin.gltf', 'w').write(json.dumps(gltf))
PY
expect_ok margin.gltf --size 16 --resolution 16 --bounces 1 --out margin
grep -q "warning: bake_scene: 2 page UVs lie outside \[0, 1\]" ok.log || { echo "FAIL: no clamp warning:"; cat ok.log; fails=$((fails + 1)); }
# A texture that cannot be read is an error naming the material and the file.
printf 'newmtl wood\nKd 1 1 1\nmap_Kd missing_wood.png\n' > wood.mtl
{ echo 'mtllib wood.mtl'; echo 'usemtl wood'; cat quad.obj; } > wood.obj
expect_fail "material" "wood" "missing_wood.png" "cannot be read" -- wood.obj --lightmap-uv 0
# A model without triangles.
printf 'v 0 0 0\nv 1 0 0\nl 1 2\n' > lines.obj
expect_fail "lines.obj" -- lines.obj --lightmap-uv 0
expect_fail "--lightmap-uv 9" -- quad.obj --lightmap-uv 9
expect_fail "--size 0" -- quad.obj --lightmap-uv 0 --size 0
expect_fail "--size 1000000" -- quad.obj --lightmap-uv 0 --size 1000000
expect_fail "--resolution 7" -- quad.obj --lightmap-uv 0 --resolution 7
expect_fail "--bounces 0" -- quad.obj --lightmap-uv 0 --bounces 0
expect_fail "--error 2" -- quad.obj --lightmap-uv 0 --error 2
expect_fail "unknown option --frobnicate" -- quad.obj --lightmap-uv 0 --frobnicate
expect_fail "--size needs a value" -- quad.obj --lightmap-uv 0 --size

[ $fails -eq 0 ] && echo "all bake CLI checks passed"
exit $fails
