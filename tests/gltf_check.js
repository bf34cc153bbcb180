// Test helper: facts of a glTF asset written by fissure --asset, read on their own (no validator).
// usage: node gltf_check.js FILE.gltf|FILE.glb plane W H | cylinder R H | sphere R   (sizes in cm)
// Checks, printing "ok ..." or "FAIL ..." per fact, exit 1 on any failure:
//  - the material binds base colour, normal and the packed occlusion-roughness-metallic texture,
//    each an existing PNG (beside the asset for .gltf, embedded for .glb), the packed one as both
//    occlusionTexture and metallicRoughnessTexture;
//  - positions are in metres, +Y up: the bounds are those of the domain (plane: x 0..W, -z 0..H to
//    2 %; cylinder: radius R to 1.2 R, the layer standing on it, around the y axis, 0..H along it;
//    sphere: radius R to 1.2 R);
//  - tangents follow the maps: on the layer's top (normal within 15 degrees of the domain's outward
//    direction, away from the sphere's poles), the tangent points the way u grows on the domain and
//    w = +1, so that cross(normal, tangent) * w points up the maps (+v), the green of the normal map
//    (99 %: slivers where the lift folded a triangle over in texture space are mirrored, and their
//    vertices rightly get w = -1).
'use strict';
const fs = require('fs');
const path = require('path');

const [file, domain, ...sizes] = process.argv.slice(2);
const dims = sizes.map(Number).map((x) => x / 100);
let failures = 0;
const check = (fact, what) => {
    console.log(`${fact ? 'ok' : 'FAIL'} ${what}`);
    if (!fact) failures++;
};

let gltf, bin;
const data = fs.readFileSync(file);
const glb = data.readUInt32LE(0) === 0x46546c67;
if (glb) {
    const jsonLen = data.readUInt32LE(12);
    gltf = JSON.parse(data.slice(20, 20 + jsonLen).toString('utf8'));
    const binStart = 20 + jsonLen;
    bin = data.slice(binStart + 8, binStart + 8 + data.readUInt32LE(binStart));
} else {
    gltf = JSON.parse(data.toString('utf8'));
    bin = fs.readFileSync(path.resolve(path.dirname(file), decodeURIComponent(gltf.buffers[0].uri)));
}
check(bin.length === gltf.buffers[0].byteLength, `the buffer holds ${bin.length} bytes, as declared`);

// Material and textures.
const mat = gltf.materials[0];
const pbr = mat.pbrMetallicRoughness;
const imageOf = (ref) => gltf.images[gltf.textures[ref.index].source];
const pngOf = (img) => {
    if (img.uri !== undefined)
        return fs.readFileSync(path.resolve(path.dirname(file), decodeURIComponent(img.uri)));
    const v = gltf.bufferViews[img.bufferView];
    return bin.slice(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength);
};
const bound = [['base colour', pbr.baseColorTexture, '_baseColor.png'], ['normal', mat.normalTexture, '_normal.png'],
               ['occlusion', mat.occlusionTexture, '_occlusionRoughnessMetallic.png'],
               ['metallic-roughness', pbr.metallicRoughnessTexture, '_occlusionRoughnessMetallic.png']];
for (const [what, ref, suffix] of bound) {
    check(ref !== undefined, `the material binds a ${what} texture`);
    if (ref === undefined) continue;
    const img = imageOf(ref);
    if (glb)
        check(img.uri === undefined && img.mimeType === 'image/png', `the ${what} image is embedded as PNG`);
    else
        check(img.uri.endsWith(suffix) && !path.isAbsolute(img.uri), `the ${what} image is ${img.uri}, relative`);
    let png;
    try { png = pngOf(img); } catch (e) { png = Buffer.alloc(0); }
    check(png.length > 8 && png.readUInt32BE(0) === 0x89504e47, `the ${what} image is a readable PNG`);
}
check(mat.occlusionTexture && pbr.metallicRoughnessTexture &&
      mat.occlusionTexture.index === pbr.metallicRoughnessTexture.index,
      'occlusion and metallic-roughness share the packed texture');

// Accessors.
const prim = gltf.meshes[0].primitives[0];
const floats = (index) => {
    const a = gltf.accessors[index], v = gltf.bufferViews[a.bufferView];
    const n = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[a.type];
    const off = (v.byteOffset || 0) + (a.byteOffset || 0);
    const out = new Float32Array(a.count * n);
    for (let i = 0; i < a.count * n; i++) out[i] = bin.readFloatLE(off + 4 * i);
    return out;
};
const P = floats(prim.attributes.POSITION), N = floats(prim.attributes.NORMAL), T = floats(prim.attributes.TANGENT);
const nv = P.length / 3;
// Back to fissure's frame (cm -> m aside): (x, y, z) = (X, -Z, Y).
const ours = (A, i) => [A[3 * i], -A[3 * i + 2], A[3 * i + 1]];
const oursT = (i) => [T[4 * i], -T[4 * i + 2], T[4 * i + 1]];
const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
for (let i = 0; i < nv; i++) {
    const p = ours(P, i);
    for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
}
const near = (a, b, size) => Math.abs(a - b) <= 0.02 * size;
const fmt = (v) => v.map((x) => x.toFixed(4)).join(' ');
if (domain === 'plane') {
    const [w, h] = dims;
    check(near(lo[0], 0, w) && near(hi[0], w, w) && near(lo[1], 0, h) && near(hi[1], h, h),
          `plane bounds ${fmt(lo)} .. ${fmt(hi)} m span ${w} x ${h} m`);
} else {
    const r = dims[0];
    const radius = (x) => x >= r * 0.999 && x <= 1.2 * r;
    check(radius(-lo[0]) && radius(hi[0]) && radius(-lo[1]) && radius(hi[1]),
          `${domain} bounds ${fmt(lo)} .. ${fmt(hi)} m: radius ${r} m, the layer on it`);
    if (domain === 'cylinder')
        check(near(lo[2], 0, dims[1]) && near(hi[2], dims[1], dims[1]), `the cylinder is ${dims[1]} m high`);
}

// Tangent frames on the layer's top.
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => { const l = Math.hypot(...a); return a.map((x) => x / l); };
let top = 0, good = 0, positive = 0;
for (let i = 0; i < nv; i++) {
    const p = ours(P, i), n = ours(N, i), t = oursT(i);
    let out, up; // outward direction and the way v grows
    if (domain === 'plane') { out = [0, 0, 1]; up = [0, 1, 0]; }
    else if (domain === 'cylinder') { out = unit([p[0], p[1], 0]); up = [0, 0, 1]; }
    else {
        out = unit(p);
        if (Math.abs(out[2]) > 0.9) continue;
        up = unit(cross(cross(out, [0, 0, 1]), out));
    }
    if (dot(n, out) < Math.cos(15 * Math.PI / 180)) continue;
    top++;
    const along = cross(up, out); // the way u grows
    if (dot(t, along) > 0.95) good++;
    if (T[4 * i + 3] === 1) positive++;
}
check(top > 100, `${top} vertices on the layer's top`);
check(good >= 0.97 * top, `${good} of ${top} top tangents point the way u grows (within 18 degrees)`);
check(positive >= 0.99 * top, `${positive} of ${top} top tangents have w = +1 (the maps are not mirrored)`);
process.exit(failures ? 1 : 0);
