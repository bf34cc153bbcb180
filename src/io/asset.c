/* Staging the 3-D outputs (--mesh OBJ + MTL, --asset glTF) with their materials bound to the maps. */
/* realpath() is an X/Open function */
#define _XOPEN_SOURCE 700
#include "io/asset.h"

#include "config.h"

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "base/error.h"
#include "geom/domain.h"
#include "io/gltf.h"
#include "io/obj.h"

/* The path from directory `from` to directory `to` (both existing), "" when they are the same
 * directory, else ending in '/', so that a file name appended to it names the file in `to`. NULL
 * with fs_error when either cannot be resolved. */
static char *relative_dir(const char *from, const char *to)
{
    char *a = realpath(from, NULL), *b = realpath(to, NULL);
    if (!a || !b) {
        fs_error(FS_ERR_IO, "%s: cannot resolve the directory: %s", a ? to : from, strerror(errno));
        free(a);
        free(b);
        return NULL;
    }
    /* the longest common prefix that ends at a component boundary */
    size_t common = 0;
    for (size_t i = 0;; i++) {
        bool end_a = a[i] == '\0' || a[i] == '/', end_b = b[i] == '\0' || b[i] == '/';
        if (end_a && end_b)
            common = i;
        if (a[i] != b[i] || a[i] == '\0')
            break;
    }
    int ups = 0;
    for (const char *p = a + common; *p; p++)
        ups += *p == '/' && p[1] != '\0';
    const char *down = b + common;
    while (*down == '/')
        down++;
    size_t n = 3 * (size_t)ups + strlen(down) + 2;
    char *rel = fs_malloc(n), *o = rel;
    for (int i = 0; i < ups; i++)
        o += sprintf(o, "../");
    if (*down)
        sprintf(o, "%s/", down);
    else
        *o = '\0';
    free(a);
    free(b);
    return rel;
}

static const fs_sidecar_map *find_map(const fs_asset_inputs *in, const char *kind)
{
    for (int i = 0; i < in->n_maps; i++)
        if (!strcmp(in->maps[i].kind, kind))
            return &in->maps[i];
    return NULL;
}

/* path with its extension (if it has one of ext_a / ext_b, any case) replaced by new_ext. */
static char *replace_ext(const char *path, const char *ext_a, const char *ext_b, const char *new_ext)
{
    size_t n = strlen(path);
    const char *exts[2] = {ext_a, ext_b};
    for (int k = 0; k < 2; k++) {
        size_t e = exts[k] ? strlen(exts[k]) : 0;
        if (e && n > e && !strcasecmp(path + n - e, exts[k])) {
            n -= e;
            break;
        }
    }
    char *out = fs_malloc(n + strlen(new_ext) + 1);
    memcpy(out, path, n);
    strcpy(out + n, new_ext);
    return out;
}

static bool is_glb(const char *path)
{
    size_t n = strlen(path);
    return n > 4 && !strcasecmp(path + n - 4, ".glb");
}

static void lift_comment(const fs_asset_inputs *in, char *buf, size_t size)
{
    const fs_config *cfg = in->cfg;
    snprintf(buf, size, "fissure %s: preset %s, seed %" PRIu64 ", %s model on a %s", PACKAGE_VERSION, cfg->preset.name,
             cfg->preset.seed, fs_model_name(cfg->preset.model), fs_domain_type_name(cfg->domain.type));
}

/* Writes the MTL of the OBJ's material `name`, the maps at rel (relative to the MTL). */
static int write_mtl(const char *path, const fs_asset_inputs *in, const char *rel)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fs_error(FS_ERR_IO, "%s: cannot create the material file: %s", path, strerror(errno));
        return -1;
    }
    const fs_config *cfg = in->cfg;
    double r = cfg->render.roughness;
    char comment[200];
    lift_comment(in, comment, sizeof comment);
    fprintf(f, "# %s\n# maps written for --target %s; texture paths are relative to this file\n", comment, in->target);
    fprintf(f, "newmtl %s\n", in->name);
    /* Ns as Blender's importer reads it back: roughness = 1 - sqrt(Ns / 1000) */
    fprintf(f, "Kd 1 1 1\nKs 0.5 0.5 0.5\nNs %.4f\nd 1\nillum 2\nPr %.4f\nPm 0\n", 1000.0 * (1.0 - r) * (1.0 - r), r);
    const fs_sidecar_map *base = find_map(in, "basecolor"), *normal = find_map(in, "normal"),
                         *height = find_map(in, "height"), *occlusion = find_map(in, "occlusion");
    if (base)
        fprintf(f, "map_Kd %s%s\n", rel, base->file);
    if (normal && cfg->render.normal == FS_NORMAL_OPENGL)
        fprintf(f, "map_Bump -bm 1 %s%s\n", rel, normal->file);
    else if (normal)
        fprintf(f, "# %s%s: DirectX normal map, not bound (MTL readers take OpenGL ones)\n", rel, normal->file);
    if (height)
        fprintf(f, "disp %s%s\n", rel, height->file);
    if (occlusion)
        fprintf(f, "# %s%s: ambient occlusion (MTL has no slot for it)\n", rel, occlusion->file);
    bool bad = ferror(f) != 0;
    if (fclose(f) != 0 || bad) {
        fs_error(FS_ERR_IO, "%s: cannot write the material file", path);
        return -1;
    }
    return 0;
}

/* Begins an output set in the directory of path; *file is path's last component, *rel the way
 * from that directory to the maps' (caller frees). NULL with fs_error on failure. */
static fs_output *begin_beside(const char *path, const fs_asset_inputs *in, const char **file, char **rel)
{
    char *dir = fs_output_dir_of(path, file);
    fs_output *out = fs_output_begin(dir);
    *rel = out ? relative_dir(dir, in->map_dir) : NULL;
    free(dir);
    if (!*rel) {
        fs_output_abort(out);
        return NULL;
    }
    return out;
}

static fs_output *stage_mesh(const fs_asset_inputs *in, const fs_lifted_mesh *lifted)
{
    const char *file;
    char *rel;
    fs_output *out = begin_beside(in->mesh_path, in, &file, &rel);
    if (!out)
        return NULL;
    char *mtl = replace_ext(file, ".obj", NULL, ".mtl");
    char comment[200];
    lift_comment(in, comment, sizeof comment);
    int rc = fs_obj_write(fs_output_stage(out, file), lifted, in->name, comment, mtl);
    if (rc == 0)
        rc = write_mtl(fs_output_stage(out, mtl), in, rel);
    free(mtl);
    free(rel);
    if (rc < 0) {
        fs_output_abort(out);
        return NULL;
    }
    return out;
}

/* The texture of a map kind for the glTF material: URI relative to the asset, staged path to read. */
static fs_gltf_texture texture_of(const fs_asset_inputs *in, const char *kind, const char *rel, char *uri_buf,
                                  size_t size)
{
    const fs_sidecar_map *m = find_map(in, kind);
    if (!m)
        return (fs_gltf_texture){NULL, NULL};
    snprintf(uri_buf, size, "%s%s", rel, m->file);
    return (fs_gltf_texture){uri_buf, fs_output_stage(in->map_out, m->file)};
}

static fs_output *stage_asset(const fs_asset_inputs *in, const fs_lifted_mesh *lifted)
{
    const char *file;
    char *rel;
    fs_output *out = begin_beside(in->asset_path, in, &file, &rel);
    if (!out)
        return NULL;
    const fs_config *cfg = in->cfg;
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    char generator[64], base_uri[PATH_MAX], normal_uri[PATH_MAX], orm_uri[PATH_MAX], height_uri[PATH_MAX];
    snprintf(generator, sizeof generator, "fissure %s", PACKAGE_VERSION);
    fs_gltf_material mat = {
        .name = in->name,
        .generator = generator,
        .base_color = texture_of(in, "basecolor", rel, base_uri, sizeof base_uri),
        .normal = texture_of(in, "normal", rel, normal_uri, sizeof normal_uri),
        .orm = texture_of(in, "occlusion", rel, orm_uri, sizeof orm_uri),
        .roughness = cfg->render.roughness,
        .wrap_u = fs_domain_wraps_u(&d),
        .wrap_v = fs_domain_wraps_v(&d),
        .double_sided = d.type != FS_DOMAIN_SPHERE,
        .height_min_cm = in->height_min_cm,
        .height_max_cm = in->height_max_cm,
    };
    const fs_sidecar_map *height = find_map(in, "height");
    if (height) {
        snprintf(height_uri, sizeof height_uri, "%s%s", rel, height->file);
        mat.height_uri = height_uri;
    }
    bool glb = is_glb(file);
    char *bin = glb ? NULL : replace_ext(file, ".gltf", NULL, ".bin");
    int rc = fs_gltf_write(fs_output_stage(out, file), bin ? fs_output_stage(out, bin) : NULL, bin, glb, lifted, &mat);
    free(bin);
    free(rel);
    if (rc < 0) {
        fs_output_abort(out);
        return NULL;
    }
    return out;
}

int fs_asset_stage(const fs_asset_inputs *in, fs_output **mesh_out, fs_output **asset_out)
{
    *mesh_out = *asset_out = NULL;
    if (!in->mesh_path && !in->asset_path)
        return 0;
    fs_lifted_mesh lifted;
    int rc = fs_render_lift(in->surface, &in->cfg->domain, 1.0, &lifted);
    if (rc == 0 && in->mesh_path && !(*mesh_out = stage_mesh(in, &lifted)))
        rc = -1;
    if (rc == 0 && in->asset_path && !(*asset_out = stage_asset(in, &lifted)))
        rc = -1;
    fs_lifted_mesh_free(&lifted);
    if (rc < 0) {
        fs_output_abort(*mesh_out);
        fs_output_abort(*asset_out);
        *mesh_out = *asset_out = NULL;
    }
    return rc;
}

/* One entry: the file at dir/file relative to the output directory. */
static int add_entry(const fs_asset_inputs *in, const char *path, const char *ext_a, const char *ext_b,
                     const char *new_ext, const char *kind, const char *usage, fs_sidecar_map *e, char *storage,
                     char *shown)
{
    const char *file;
    char *dir = fs_output_dir_of(path, &file);
    char *rel = relative_dir(in->map_dir, dir);
    free(dir);
    if (!rel)
        return 0;
    char *name = new_ext ? replace_ext(file, ext_a, ext_b, new_ext) : fs_strdup(file);
    snprintf(storage, 1024, "%s%s", rel, name);
    snprintf(shown, 1024, "%.*s%s", (int)(file - path), path, name);
    free(name);
    free(rel);
    *e = (fs_sidecar_map){kind, storage, NULL, "data", NULL, usage};
    return 1;
}

int fs_asset_files(const fs_asset_inputs *in, fs_sidecar_map *list, char (*storage)[1024], char (*paths)[1024])
{
    int n = 0;
    if (in->mesh_path) {
        n += add_entry(in, in->mesh_path, NULL, NULL, NULL, "mesh",
                       "Wavefront OBJ of the cracked layer (cm, z up), material from its MTL", &list[n], storage[n], paths[n]);
        n += add_entry(in, in->mesh_path, ".obj", NULL, ".mtl", "mesh_material",
                       "Wavefront MTL: map_Kd base colour, map_Bump normal map (OpenGL), disp height, Ns/Pr "
                       "roughness; occlusion has no MTL slot",
                       &list[n], storage[n], paths[n]);
    }
    if (in->asset_path) {
        bool glb = is_glb(in->asset_path);
        n += add_entry(in, in->asset_path, NULL, NULL, NULL, "asset",
                       glb ? "binary glTF 2.0 asset (metres, +Y up) embedding its buffer and images: metallic-roughness "
                             "material with base colour, normal and occlusion-roughness-metallic textures; the height "
                             "map is not bound (glTF 2.0 has no height slot) and is named in material.extras"
                           : "glTF 2.0 asset (metres, +Y up): metallic-roughness material with base colour, normal and "
                             "occlusion-roughness-metallic textures at paths relative to it; the height map is not "
                             "bound (glTF 2.0 has no height slot) and is named in material.extras",
                       &list[n], storage[n], paths[n]);
        if (!glb)
            n += add_entry(in, in->asset_path, ".gltf", NULL, ".bin", "asset_buffer",
                           "the glTF asset's binary buffer (indices, positions, normals, tangents, texture coordinates)",
                           &list[n], storage[n], paths[n]);
    }
    return n;
}
