/* glTF 2.0 assets (.gltf with a .bin buffer, or one .glb) of a lifted mesh and its material. */
#include "io/gltf.h"

#include <errno.h>
#include <float.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "geom/tangent.h"
#include "io/json.h"

enum {
    GL_UNSIGNED_INT = 5125,
    GL_FLOAT = 5126,
    GL_ARRAY_BUFFER = 34962,
    GL_ELEMENT_ARRAY_BUFFER = 34963,
    GL_TRIANGLES = 4,
    GL_LINEAR = 9729,
    GL_LINEAR_MIPMAP_LINEAR = 9987,
    GL_REPEAT = 10497,
    GL_CLAMP_TO_EDGE = 33071,
};

/* The binary buffer, little-endian whatever the machine. */
typedef struct {
    uint8_t *data;
    size_t n, cap;
} bytes;

static void reserve(bytes *b, size_t more)
{
    if (b->n + more <= b->cap)
        return;
    while (b->n + more > b->cap)
        b->cap = b->cap ? 2 * b->cap : 1 << 16;
    b->data = fs_realloc(b->data, b->cap);
}

static void put_u32(bytes *b, uint32_t v)
{
    reserve(b, 4);
    for (int k = 0; k < 4; k++)
        b->data[b->n++] = (uint8_t)(v >> (8 * k));
}

static void put_f32(bytes *b, float f)
{
    uint32_t v;
    memcpy(&v, &f, sizeof v);
    put_u32(b, v);
}

static void put_raw(bytes *b, const void *p, size_t n)
{
    reserve(b, n);
    memcpy(b->data + b->n, p, n);
    b->n += n;
}

static void pad4(bytes *b, uint8_t fill)
{
    while (b->n % 4) {
        reserve(b, 1);
        b->data[b->n++] = fill;
    }
}

/* Appends a buffer view of the bytes written since `start` (4-byte aligned) to views; returns its index. */
static int add_view(fs_json *views, size_t start, size_t end, int target)
{
    fs_json *v = fs_json_object();
    fs_json_set(v, "buffer", fs_json_integer(0));
    fs_json_set(v, "byteOffset", fs_json_integer((int64_t)start));
    fs_json_set(v, "byteLength", fs_json_integer((int64_t)(end - start)));
    if (target)
        fs_json_set(v, "target", fs_json_integer(target));
    fs_json_append(views, v);
    return (int)fs_json_size(views) - 1;
}

static fs_json *float_array(const float *x, int n)
{
    fs_json *a = fs_json_array();
    for (int i = 0; i < n; i++)
        fs_json_append(a, fs_json_real((double)x[i]));
    return a;
}

static int add_accessor(fs_json *accessors, int view, int component, int64_t count, const char *type,
                        const float *min, const float *max, int n_minmax)
{
    fs_json *a = fs_json_object();
    fs_json_set(a, "bufferView", fs_json_integer(view));
    fs_json_set(a, "componentType", fs_json_integer(component));
    fs_json_set(a, "count", fs_json_integer(count));
    fs_json_set(a, "type", fs_json_string(type));
    if (min) {
        fs_json_set(a, "min", float_array(min, n_minmax));
        fs_json_set(a, "max", float_array(max, n_minmax));
    }
    fs_json_append(accessors, a);
    return (int)fs_json_size(accessors) - 1;
}

/* The URI of a relative path: unreserved characters and '/' kept, everything else percent-encoded. */
static char *uri_encode(const char *path)
{
    static const char hex[] = "0123456789ABCDEF";
    char *out = fs_malloc(3 * strlen(path) + 1), *o = out;
    for (const unsigned char *p = (const unsigned char *)path; *p; p++) {
        if ((*p >= 'A' && *p <= 'Z') || (*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || strchr("-._~/", *p)) {
            *o++ = (char)*p;
        } else {
            *o++ = '%';
            *o++ = hex[*p >> 4];
            *o++ = hex[*p & 15];
        }
    }
    *o = '\0';
    return out;
}

static int read_file(const char *path, bytes *b)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fs_error(FS_ERR_IO, "%s: cannot read the image to embed: %s", path, strerror(errno));
        return -1;
    }
    uint8_t chunk[1 << 15];
    size_t got;
    while ((got = fread(chunk, 1, sizeof chunk, f)) > 0)
        put_raw(b, chunk, got);
    bool bad = ferror(f) != 0;
    fclose(f);
    if (bad) {
        fs_error(FS_ERR_IO, "%s: cannot read the image to embed", path);
        return -1;
    }
    return 0;
}

/* Adds the image and texture of t (if bound); returns the texture index or -1. */
static int add_texture(fs_json *root, const fs_gltf_texture *t, bool glb, bytes *bin, fs_json *views, int *status)
{
    if (!t->uri || *status < 0)
        return -1;
    fs_json *images = fs_json_get(root, "images"), *textures = fs_json_get(root, "textures");
    fs_json *img = fs_json_object();
    /* named after its file, without directory and extension (Blender names embedded images so) */
    const char *base = strrchr(t->uri, '/') ? strrchr(t->uri, '/') + 1 : t->uri;
    const char *dot = strrchr(base, '.');
    char name[256];
    snprintf(name, sizeof name, "%.*s", (int)(dot && dot != base ? dot - base : (ptrdiff_t)strlen(base)), base);
    fs_json_set(img, "name", fs_json_string(name));
    if (glb) {
        size_t start = bin->n;
        if (read_file(t->read_path, bin) < 0) {
            fs_json_free(img);
            *status = -1;
            return -1;
        }
        int view = add_view(views, start, bin->n, 0);
        pad4(bin, 0);
        fs_json_set(img, "bufferView", fs_json_integer(view));
        fs_json_set(img, "mimeType", fs_json_string("image/png"));
    } else {
        char *uri = uri_encode(t->uri);
        fs_json_set(img, "uri", fs_json_string(uri));
        free(uri);
    }
    fs_json_append(images, img);
    fs_json *tex = fs_json_object();
    fs_json_set(tex, "sampler", fs_json_integer(0));
    fs_json_set(tex, "source", fs_json_integer((int64_t)fs_json_size(images) - 1));
    fs_json_append(textures, tex);
    return (int)fs_json_size(textures) - 1;
}

static fs_json *texture_ref(int index)
{
    fs_json *r = fs_json_object();
    fs_json_set(r, "index", fs_json_integer(index));
    return r;
}

/* The glTF frame: metres, +Y up. */
static void to_gltf(const double *cm, float *out)
{
    out[0] = (float)(cm[0] / 100.0);
    out[1] = (float)(cm[2] / 100.0);
    out[2] = (float)(-cm[1] / 100.0);
}

static void dir_to_gltf(const float *d, float *out)
{
    out[0] = d[0];
    out[1] = d[2];
    out[2] = -d[1];
}

static int write_bytes(const char *path, const uint8_t *data, size_t n, const char *what)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        fs_error(FS_ERR_IO, "%s: cannot create the %s: %s", path, what, strerror(errno));
        return -1;
    }
    bool bad = fwrite(data, 1, n, f) != n;
    bad = fclose(f) != 0 || bad;
    if (bad) {
        fs_error(FS_ERR_IO, "%s: cannot write the %s", path, what);
        return -1;
    }
    return 0;
}

int fs_gltf_write(const char *path, const char *bin_path, const char *bin_uri, bool glb, const fs_lifted_mesh *m,
                  const fs_gltf_material *mat)
{
    /* Vertices: one per distinct (position, texture vertex, normal), tangents where mirrored
     * texture mapping splits them. */
    int32_t *vert;
    uint32_t *tri;
    int32_t n_vert = fs_lifted_mesh_vertices(m, &vert, &tri);
    float *pos = fs_malloc((3 * (size_t)n_vert + 1) * sizeof *pos);
    float *nrm = fs_malloc((3 * (size_t)n_vert + 1) * sizeof *nrm);
    float *uv = fs_malloc((2 * (size_t)n_vert + 1) * sizeof *uv);
    int32_t *pos_id = fs_malloc(((size_t)n_vert + 1) * sizeof *pos_id);
    for (int32_t i = 0; i < n_vert; i++) {
        const int32_t *c = vert + 3 * (size_t)i;
        for (int q = 0; q < 3; q++) {
            pos[3 * (size_t)i + q] = (float)m->pos[3 * (size_t)c[0] + q];
            nrm[3 * (size_t)i + q] = m->normal[3 * (size_t)c[2] + q];
        }
        uv[2 * (size_t)i] = m->uv[2 * (size_t)c[1]];
        uv[2 * (size_t)i + 1] = m->uv[2 * (size_t)c[1] + 1];
        pos_id[i] = c[0];
    }
    const bool tangents = mat->normal.uri != NULL;
    int32_t *source = NULL;
    float *tangent = NULL;
    int32_t n_out = n_vert;
    if (tangents)
        n_out = fs_tangents_build(pos, nrm, uv, pos_id, n_vert, tri, m->n_tris, &source, &tangent);
    free(pos_id);
    free(pos);

    fs_json *root = fs_json_object();
    fs_json *asset = fs_json_object();
    fs_json_set(asset, "version", fs_json_string("2.0"));
    fs_json_set(asset, "generator", fs_json_string(mat->generator));
    fs_json_set(root, "asset", asset);
    fs_json_set(root, "scene", fs_json_integer(0));
    fs_json *scenes = fs_json_array(), *scene = fs_json_object(), *scene_nodes = fs_json_array();
    fs_json_append(scene_nodes, fs_json_integer(0));
    fs_json_set(scene, "name", fs_json_string(mat->name));
    fs_json_set(scene, "nodes", scene_nodes);
    fs_json_append(scenes, scene);
    fs_json_set(root, "scenes", scenes);
    fs_json *nodes = fs_json_array(), *node = fs_json_object();
    fs_json_set(node, "name", fs_json_string(mat->name));
    fs_json_set(node, "mesh", fs_json_integer(0));
    fs_json_append(nodes, node);
    fs_json_set(root, "nodes", nodes);

    fs_json *views = fs_json_array(), *accessors = fs_json_array();
    bytes bin = {0};
    /* indices */
    size_t start = bin.n;
    for (size_t k = 0; k < 3 * (size_t)m->n_tris; k++)
        put_u32(&bin, tri[k]);
    int acc_index = add_accessor(accessors, add_view(views, start, bin.n, GL_ELEMENT_ARRAY_BUFFER), GL_UNSIGNED_INT,
                                 3 * (int64_t)m->n_tris, "SCALAR", NULL, NULL, 0);
    /* positions, with their bounds (which glTF requires) */
    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    start = bin.n;
    for (int32_t i = 0; i < n_out; i++) {
        int32_t s = source ? source[i] : i;
        float p[3];
        to_gltf(m->pos + 3 * (size_t)vert[3 * (size_t)s], p);
        for (int q = 0; q < 3; q++) {
            put_f32(&bin, p[q]);
            lo[q] = p[q] < lo[q] ? p[q] : lo[q];
            hi[q] = p[q] > hi[q] ? p[q] : hi[q];
        }
    }
    int acc_pos = add_accessor(accessors, add_view(views, start, bin.n, GL_ARRAY_BUFFER), GL_FLOAT, n_out, "VEC3", lo,
                               hi, 3);
    start = bin.n;
    for (int32_t i = 0; i < n_out; i++) {
        float d[3];
        dir_to_gltf(nrm + 3 * (size_t)(source ? source[i] : i), d);
        for (int q = 0; q < 3; q++)
            put_f32(&bin, d[q]);
    }
    int acc_nrm = add_accessor(accessors, add_view(views, start, bin.n, GL_ARRAY_BUFFER), GL_FLOAT, n_out, "VEC3", NULL,
                               NULL, 0);
    int acc_tan = -1;
    if (tangents) {
        start = bin.n;
        for (int32_t i = 0; i < n_out; i++) {
            float d[3];
            dir_to_gltf(tangent + 4 * (size_t)i, d);
            for (int q = 0; q < 3; q++)
                put_f32(&bin, d[q]);
            put_f32(&bin, tangent[4 * (size_t)i + 3]);
        }
        acc_tan = add_accessor(accessors, add_view(views, start, bin.n, GL_ARRAY_BUFFER), GL_FLOAT, n_out, "VEC4",
                               NULL, NULL, 0);
    }
    start = bin.n;
    for (int32_t i = 0; i < n_out; i++) {
        int32_t s = source ? source[i] : i;
        put_f32(&bin, uv[2 * (size_t)s]);
        put_f32(&bin, 1.0f - uv[2 * (size_t)s + 1]);
    }
    int acc_uv = add_accessor(accessors, add_view(views, start, bin.n, GL_ARRAY_BUFFER), GL_FLOAT, n_out, "VEC2", NULL,
                              NULL, 0);
    free(vert);
    free(tri);
    free(nrm);
    free(uv);
    free(source);
    free(tangent);

    fs_json *attributes = fs_json_object();
    fs_json_set(attributes, "POSITION", fs_json_integer(acc_pos));
    fs_json_set(attributes, "NORMAL", fs_json_integer(acc_nrm));
    if (acc_tan >= 0)
        fs_json_set(attributes, "TANGENT", fs_json_integer(acc_tan));
    fs_json_set(attributes, "TEXCOORD_0", fs_json_integer(acc_uv));
    fs_json *prim = fs_json_object();
    fs_json_set(prim, "attributes", attributes);
    fs_json_set(prim, "indices", fs_json_integer(acc_index));
    fs_json_set(prim, "material", fs_json_integer(0));
    fs_json_set(prim, "mode", fs_json_integer(GL_TRIANGLES));
    fs_json *prims = fs_json_array(), *meshes = fs_json_array(), *mesh = fs_json_object();
    fs_json_append(prims, prim);
    fs_json_set(mesh, "name", fs_json_string(mat->name));
    fs_json_set(mesh, "primitives", prims);
    fs_json_append(meshes, mesh);
    fs_json_set(root, "meshes", meshes);

    /* The material and its textures (embedded after the geometry in a .glb). */
    pad4(&bin, 0);
    bool any = mat->base_color.uri || mat->normal.uri || mat->orm.uri;
    int status = 0;
    if (any) {
        fs_json *samplers = fs_json_array(), *sampler = fs_json_object();
        fs_json_set(sampler, "magFilter", fs_json_integer(GL_LINEAR));
        fs_json_set(sampler, "minFilter", fs_json_integer(GL_LINEAR_MIPMAP_LINEAR));
        fs_json_set(sampler, "wrapS", fs_json_integer(mat->wrap_u ? GL_REPEAT : GL_CLAMP_TO_EDGE));
        fs_json_set(sampler, "wrapT", fs_json_integer(mat->wrap_v ? GL_REPEAT : GL_CLAMP_TO_EDGE));
        fs_json_append(samplers, sampler);
        fs_json_set(root, "samplers", samplers);
        fs_json_set(root, "images", fs_json_array());
        fs_json_set(root, "textures", fs_json_array());
    }
    int t_base = add_texture(root, &mat->base_color, glb, &bin, views, &status);
    int t_normal = add_texture(root, &mat->normal, glb, &bin, views, &status);
    int t_orm = add_texture(root, &mat->orm, glb, &bin, views, &status);
    fs_json *material = fs_json_object(), *pbr = fs_json_object();
    fs_json_set(material, "name", fs_json_string(mat->name));
    if (t_base >= 0)
        fs_json_set(pbr, "baseColorTexture", texture_ref(t_base));
    fs_json_set(pbr, "metallicFactor", fs_json_real(t_orm >= 0 ? 1.0 : 0.0));
    fs_json_set(pbr, "roughnessFactor", fs_json_real(t_orm >= 0 ? 1.0 : mat->roughness));
    if (t_orm >= 0)
        fs_json_set(pbr, "metallicRoughnessTexture", texture_ref(t_orm));
    fs_json_set(material, "pbrMetallicRoughness", pbr);
    if (t_normal >= 0)
        fs_json_set(material, "normalTexture", texture_ref(t_normal));
    if (t_orm >= 0)
        fs_json_set(material, "occlusionTexture", texture_ref(t_orm));
    fs_json_set(material, "doubleSided", fs_json_bool(mat->double_sided));
    if (mat->height_uri) {
        fs_json *extras = fs_json_object();
        fs_json_set(extras, "height_map", fs_json_string(mat->height_uri));
        fs_json_set(extras, "height_min_cm", fs_json_real(mat->height_min_cm));
        fs_json_set(extras, "height_max_cm", fs_json_real(mat->height_max_cm));
        fs_json_set(extras, "note", fs_json_string("glTF 2.0 has no height or displacement slot: the height map is "
                                                   "named here, not bound"));
        fs_json_set(material, "extras", extras);
    }
    fs_json *materials = fs_json_array();
    fs_json_append(materials, material);
    fs_json_set(root, "materials", materials);

    fs_json *buffers = fs_json_array(), *buffer = fs_json_object();
    fs_json_set(buffer, "byteLength", fs_json_integer((int64_t)bin.n));
    if (!glb) {
        char *uri = uri_encode(bin_uri);
        fs_json_set(buffer, "uri", fs_json_string(uri));
        free(uri);
    }
    fs_json_append(buffers, buffer);
    fs_json_set(root, "buffers", buffers);
    fs_json_set(root, "bufferViews", views);
    fs_json_set(root, "accessors", accessors);

    const fs_json_format fmt = {glb ? 0 : 1, 0};
    if (status == 0 && !glb) {
        if (fs_json_write(root, path, fmt) < 0) {
            fs_error(FS_ERR_IO, "%s: cannot write the glTF asset", path);
            status = -1;
        } else {
            status = write_bytes(bin_path, bin.data, bin.n, "glTF buffer");
        }
    } else if (status == 0) {
        char *json = fs_json_dump(root, fmt);
        FS_ASSERT(json);
        bytes glb_bytes = {0};
        size_t json_len = strlen(json), json_padded = (json_len + 3) / 4 * 4;
        size_t total = 12 + 8 + json_padded + 8 + bin.n;
        put_u32(&glb_bytes, 0x46546C67u); /* "glTF" */
        put_u32(&glb_bytes, 2);
        put_u32(&glb_bytes, (uint32_t)total);
        put_u32(&glb_bytes, (uint32_t)json_padded);
        put_u32(&glb_bytes, 0x4E4F534Au); /* "JSON" */
        put_raw(&glb_bytes, json, json_len);
        pad4(&glb_bytes, ' ');
        put_u32(&glb_bytes, (uint32_t)bin.n);
        put_u32(&glb_bytes, 0x004E4942u); /* "BIN" */
        put_raw(&glb_bytes, bin.data, bin.n);
        free(json);
        if (total > UINT32_MAX) {
            fs_error(FS_ERR_DATA, "%s: the mesh is too large for a binary glTF file (%zu bytes, 4 GiB at most)", path,
                     total);
            status = -1;
        } else {
            status = write_bytes(path, glb_bytes.data, glb_bytes.n, "binary glTF asset");
        }
        free(glb_bytes.data);
    }
    free(bin.data);
    fs_json_free(root);
    return status;
}
