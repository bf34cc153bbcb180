# Test helper run inside Blender: imports an asset fissure wrote, checks that its material has the
# maps bound where Blender's importer puts them, and renders one frame.
# usage: blender -b --factory-startup --python-exit-code 1 --python tests/blender_check.py -- \
#            gltf|obj FILE RENDER.png
# For a .gltf, also compares its tangents with those of Blender's MikkTSpace on the same mesh.
# Prints one "ok ..." line per fact; raises (so Blender exits 1) at the first that does not hold.
import json
import math
import os
import sys

import bpy
import mathutils
import numpy

# Debian 12's Blender 3.4 glTF importer still uses numpy.bool, an alias numpy 1.24 (Debian 12's)
# removed; give it back, as it was (the builtin bool), so the importer runs.
if "bool" not in numpy.__dict__:
    numpy.bool = bool

argv = sys.argv[sys.argv.index("--") + 1:]
mode, path, render_path = argv

bpy.ops.wm.read_factory_settings(use_empty=True)
if mode == "gltf":
    bpy.ops.import_scene.gltf(filepath=path)
else:
    # fissure's OBJ is z up, in cm
    bpy.ops.wm.obj_import(filepath=path, forward_axis="Y", up_axis="Z")


def check(fact, what):
    if not fact:
        raise AssertionError("FAIL " + what)
    print("ok " + what)


meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
check(len(meshes) == 1, "one mesh object imported (%d)" % len(meshes))
obj = meshes[0]
check(len(obj.data.polygons) > 100, "the mesh has %d faces" % len(obj.data.polygons))
check(len(obj.data.uv_layers) == 1, "the mesh has its texture coordinates")
mats = [s.material for s in obj.material_slots if s.material]
check(len(mats) == 1, "one material bound to the mesh")
mat = mats[0]
nodes = mat.node_tree.nodes
bsdf = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
check(bsdf is not None, "material %s has a Principled BSDF" % mat.name)


def image_into(socket, hops=2):
    """The image texture node feeding socket, through at most `hops` other nodes (normal map,
    separate RGB), or None."""
    for link in socket.links:
        node = link.from_node
        if node.type == "TEX_IMAGE":
            return node
        if hops > 0:
            for inp in node.inputs:
                found = image_into(inp, hops - 1)
                if found:
                    return found
    return None


def loaded(node, suffix, what):
    check(node is not None and node.image is not None, what + " is an image texture")
    img = node.image
    # an image read from a file has its path; one embedded in a .glb only its name
    name = os.path.basename(img.filepath) if img.filepath else img.name + ".png"
    check(name.lower().endswith(suffix.lower()), "%s is %s (%s)" % (what, suffix, name))
    check(img.size[0] > 0 and img.size[1] > 0 and len(img.pixels) == 4 * img.size[0] * img.size[1],
          "%s's pixels load (%dx%d)" % (what, img.size[0], img.size[1]))
    return img


loaded(image_into(bsdf.inputs["Base Color"]), "_basecolor.png", "Base Color")
normal = image_into(bsdf.inputs["Normal"])
check(any(l.from_node.type == "NORMAL_MAP" for l in bsdf.inputs["Normal"].links),
      "Normal comes through a tangent-space Normal Map node")
loaded(normal, "_normal.png", "Normal")
if mode == "gltf":
    img = loaded(image_into(bsdf.inputs["Roughness"]), "_occlusionRoughnessMetallic.png", "Roughness")
    check(img.colorspace_settings.name == "Non-Color", "the packed map is read as Non-Color")
    loaded(image_into(bsdf.inputs["Metallic"]), "_occlusionRoughnessMetallic.png", "Metallic")
    check(normal.image.colorspace_settings.name == "Non-Color", "the normal map is read as Non-Color")


def gltf_tangents(path):
    """Per (position, texture coordinate) the tangents of a .gltf's vertices, in Blender's frame."""
    with open(path) as f:
        g = json.load(f)
    with open(os.path.join(os.path.dirname(path), g["buffers"][0]["uri"]), "rb") as f:
        data = f.read()

    def floats(index):
        a = g["accessors"][index]
        n = {"VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
        off = g["bufferViews"][a["bufferView"]].get("byteOffset", 0)
        return numpy.frombuffer(data, dtype="<f4", count=a["count"] * n, offset=off).reshape(-1, n).astype(float)

    attr = g["meshes"][0]["primitives"][0]["attributes"]
    p, t, uv = floats(attr["POSITION"]), floats(attr["TANGENT"]), floats(attr["TEXCOORD_0"])
    table = {}
    for i in range(len(p)):
        # glTF (x, y, z) is Blender's (x, -z, y); Blender's v is 1 - t
        k = key((p[i][0], -p[i][2], p[i][1]), (uv[i][0], 1.0 - uv[i][1]))
        table.setdefault(k, []).append((t[i][0], -t[i][2], t[i][1], t[i][3]))
    return table


def key(p, uv):
    return tuple(round(float(x), 6) for x in (p[0], p[1], p[2], uv[0], uv[1]))


# Tangents against Blender's own MikkTSpace (mesh.calc_tangents) on the same mesh. Blender 3.4
# computes some loops' tangents against other normals than the imported ones (its tangent is then
# not perpendicular to the loop's normal); where it used the same normals, ours must agree, but
# for the crack walls, which have no area in texture space and where both fall back on a guess.
if mode == "gltf" and path.endswith(".gltf"):
    me = obj.data
    me.calc_tangents(uvmap=me.uv_layers[0].name)
    me.calc_normals_split()
    ours = gltf_tangents(path)
    uvs = me.uv_layers[0].data
    same_normals = agree = 0
    for lp in me.loops:
        bt, bn = lp.tangent, lp.normal
        if abs(bt.dot(bn)) > 0.05:
            continue
        same_normals += 1
        cands = ours.get(key(obj.matrix_world @ me.vertices[lp.vertex_index].co, uvs[lp.index].uv), [])
        agree += any(c[0] * bt[0] + c[1] * bt[1] + c[2] * bt[2] > math.cos(math.radians(10)) and
                     c[3] == lp.bitangent_sign for c in cands)
    check(same_normals > 0.5 * len(me.loops) and agree >= 0.98 * same_normals,
          "the tangents agree with Blender's MikkTSpace within 10 degrees and in sign on %d of the %d loops "
          "where it used the same normals (%d loops in all)" % (agree, same_normals, len(me.loops)))

# One frame: Cycles on the CPU, a sun, and an orthographic camera looking at the object along its
# thinnest axis (down on a tile, at the side of a trunk, down on a sphere's pole).
scene = bpy.context.scene
lo = [min(v[k] for v in obj.bound_box) for k in range(3)]
hi = [max(v[k] for v in obj.bound_box) for k in range(3)]
world = [obj.matrix_world @ mathutils.Vector(c) for c in ((lo[0], lo[1], lo[2]), (hi[0], hi[1], hi[2]))]
centre = [(world[0][k] + world[1][k]) / 2 for k in range(3)]
size = max(abs(world[1][k] - world[0][k]) for k in range(3))
cam_data = bpy.data.cameras.new("camera")
cam_data.type = "ORTHO"
cam_data.ortho_scale = 1.1 * size
cam_data.clip_start = 0.01 * size
cam_data.clip_end = 10 * size
cam = bpy.data.objects.new("camera", cam_data)
thin = min(range(3), key=lambda k: (abs(world[1][k] - world[0][k]), -k))
eye = list(centre)
eye[thin] = max(world[0][thin], world[1][thin]) + size
cam.location = eye
# a camera looks along its -z: turned to look down -x, -y or -z
cam.rotation_euler = [(0.0, math.pi / 2, 0.0), (-math.pi / 2, 0.0, 0.0), (0.0, 0.0, 0.0)][thin]
scene.collection.objects.link(cam)
scene.camera = cam
sun_data = bpy.data.lights.new("sun", "SUN")
sun_data.energy = 3.0
sun = bpy.data.objects.new("sun", sun_data)
sun.rotation_euler = cam.rotation_euler  # light from the camera's side
scene.collection.objects.link(sun)
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 4
scene.cycles.use_denoising = False
scene.render.resolution_x = scene.render.resolution_y = 48
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "PNG"
scene.render.filepath = render_path
bpy.ops.render.render(write_still=True)
check(os.path.getsize(render_path) > 0, "one frame rendered to " + render_path)
frame = bpy.data.images.load(render_path)
px = list(frame.pixels)
lum = [0.2126 * px[i] + 0.7152 * px[i + 1] + 0.0722 * px[i + 2] for i in range(0, len(px), 4)]
w, h = frame.size
centre_lum = lum[(h // 2) * w + w // 2]
check(max(lum) - min(lum) > 0.02, "the frame shows the textured layer (luminance %.3f to %.3f)" % (min(lum), max(lum)))
check(centre_lum > 0.01, "the centre of the frame is lit (luminance %.3f)" % centre_lum)
