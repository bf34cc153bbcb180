/* The JSON sidecar: what was run (resolved preset, seed), what happened (stats) and what each map holds. */
#include "io/sidecar.h"

#include "config.h"

#include <errno.h>
#include <jansson.h>
#include <stdbool.h>
#include <string.h>

#include "base/error.h"
#include "geom/domain.h"
#include "io/preset.h"

/* FNV-1a, 64-bit: a stable fingerprint of the preset text (not a security hash). */
static uint64_t fnv1a64(const char *s)
{
    uint64_t h = UINT64_C(0xcbf29ce484222325);
    for (; *s; s++) {
        h ^= (unsigned char)*s;
        h *= UINT64_C(0x100000001b3);
    }
    return h;
}

static void visit_param(void *ctx, const char *section, const char *key, const char *value)
{
    json_t *params = ctx;
    json_t *sec = json_object_get(params, section);
    if (!sec) {
        sec = json_object();
        json_object_set_new(params, section, sec);
    }
    json_object_set_new(sec, key, json_string(value));
}

static int bit_depth(const fs_image *img)
{
    switch (img->type) {
    case FS_PIX_U8: return 8;
    case FS_PIX_U16: return 16;
    case FS_PIX_F32: return 32;
    }
    return 0;
}

static json_t *map_entry(const fs_sidecar_map *m, const fs_config *cfg, const fs_maps *maps)
{
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    json_t *e = json_object();
    json_object_set_new(e, "file", json_string(m->file));
    if (m->usage)
        json_object_set_new(e, "usage", json_string(m->usage));
    if (m->channels)
        json_object_set_new(e, "channels_meaning", json_string(m->channels));
    if (!m->image)
        return e;
    json_object_set_new(e, "color_space", json_string(m->color_space));
    if (m->image->type != FS_PIX_F32)
        json_object_set_new(e, "png_color_chunk",
                            json_string(!strcmp(m->color_space, "srgb") ? "sRGB" : "none (raw values)"));
    json_object_set_new(e, "bit_depth", json_integer(bit_depth(m->image)));
    json_object_set_new(e, "sample_format", json_string(m->image->type == FS_PIX_F32 ? "float" : "unsigned"));
    json_object_set_new(e, "channels", json_integer(m->image->channels));
    json_object_set_new(e, "width", json_integer(m->image->width));
    json_object_set_new(e, "height", json_integer(m->image->height));
    /* a perspective view of the object never tiles, whatever the domain does */
    bool texture_space = strcmp(m->kind, "preview") != 0;
    json_t *tile = json_object();
    json_object_set_new(tile, "u", json_boolean(texture_space && fs_domain_wraps_u(&d)));
    json_object_set_new(tile, "v", json_boolean(texture_space && fs_domain_wraps_v(&d)));
    json_object_set_new(e, "tileable", tile);
    if (!strcmp(m->kind, "height")) {
        json_object_set_new(e, "height_min_cm", json_real(maps->height_min_cm));
        json_object_set_new(e, "height_max_cm", json_real(maps->height_max_cm));
        json_object_set_new(e, "height_scale_cm", json_real(maps->height_max_cm - maps->height_min_cm));
        json_object_set_new(e, "encoding", json_string(m->image->type == FS_PIX_F32
                                                           ? "height in cm"
                                                           : "0 = height_min_cm, full scale = height_max_cm, linear"));
    } else if (!strcmp(m->kind, "normal")) {
        json_object_set_new(e, "normal_convention",
                            json_string(cfg->render.normal == FS_NORMAL_DIRECTX ? "directx" : "opengl"));
        json_object_set_new(e, "height_scale", json_real(cfg->render.height_scale));
    } else if (!strcmp(m->kind, "crackdist")) {
        json_object_set_new(e, "units_per_pixel", json_real(maps->crackdist_scale));
    } else if (!strcmp(m->kind, "cellid")) {
        json_object_set_new(e, "encoding", json_string("fragment id, 0 = crack"));
    } else if (!strcmp(m->kind, "crackmask")) {
        json_object_set_new(e, "encoding", json_string("crack coverage, 255 = crack"));
    } else if (!strcmp(m->kind, "occlusion") || !strcmp(m->kind, "roughness")) {
        json_object_set_new(e, "roughness", json_real(cfg->render.roughness));
    }
    return e;
}

int fs_sidecar_write(const char *path, const fs_config *cfg, const char *preset_text, const fs_stats *stats,
                     const fs_maps *maps, const char *target, const fs_sidecar_map *list, int n_maps,
                     const fs_sidecar_frames *frames, const char *const *files, int n_files, double wall_seconds)
{
    json_t *root = json_object();
    json_object_set_new(root, "generator", json_string("fissure"));
    json_object_set_new(root, "version", json_string(PACKAGE_VERSION));

    json_t *preset = json_object();
    json_object_set_new(preset, "name", json_string(cfg->preset.name));
    if (preset_text) {
        char hash[32];
        snprintf(hash, sizeof hash, "fnv1a64:%016llx", (unsigned long long)fnv1a64(preset_text));
        json_object_set_new(preset, "hash", json_string(hash));
    }
    json_object_set_new(root, "preset", preset);
    json_object_set_new(root, "seed", json_integer((json_int_t)cfg->preset.seed));

    json_t *params = json_object();
    fs_preset_visit(cfg, visit_param, params);
    json_object_set_new(root, "parameters", params);

    json_t *st = json_object();
    json_object_set_new(st, "nodes", json_integer(stats->nodes));
    json_object_set_new(st, "elements", json_integer(stats->elements));
    json_object_set_new(st, "fractures", json_integer(stats->fractures));
    json_object_set_new(st, "simulated_time", json_real(stats->simulated_time));
    json_object_set_new(st, "wall_seconds", json_real(wall_seconds));
    json_object_set_new(root, "stats", st);

    json_object_set_new(root, "target", json_string(target));
    json_t *jm = json_object();
    for (int i = 0; i < n_maps; i++)
        json_object_set_new(jm, list[i].kind, map_entry(&list[i], cfg, maps));
    json_object_set_new(root, "maps", jm);

    if (frames) {
        json_t *jf = json_object();
        json_object_set_new(jf, "count", json_integer(frames->count));
        json_object_set_new(jf, "file_pattern", json_string(frames->file_pattern));
        json_t *kinds = json_object();
        for (int i = 0; i < frames->n_maps; i++) {
            json_t *e = map_entry(&frames->map[i], cfg, maps);
            /* each frame's height map has its own range, listed per frame below */
            json_object_del(e, "height_min_cm");
            json_object_del(e, "height_max_cm");
            json_object_del(e, "height_scale_cm");
            json_object_set_new(kinds, frames->map[i].kind, e);
        }
        json_object_set_new(jf, "maps", kinds);
        json_t *list_f = json_array();
        for (int32_t k = 0; k < frames->count; k++) {
            json_t *f = json_object();
            json_object_set_new(f, "frame", json_integer(k + 1));
            json_object_set_new(f, "time", json_real(frames->time[k]));
            json_object_set_new(f, "fractures", json_integer(frames->fractures[k]));
            json_object_set_new(f, "height_min_cm", json_real(frames->height_min_cm[k]));
            json_object_set_new(f, "height_max_cm", json_real(frames->height_max_cm[k]));
            json_array_append_new(list_f, f);
        }
        json_object_set_new(jf, "frames", list_f);
        json_object_set_new(root, "frames", jf);
    }

    json_t *jfiles = json_array();
    for (int i = 0; i < n_files; i++) {
        json_t *f = json_string(files[i]);
        if (!f) {
            json_decref(jfiles);
            json_decref(root);
            fs_error(FS_ERR_CANTCREAT, "%s: the sidecar cannot list a file name that is not UTF-8", files[i]);
            return -1;
        }
        json_array_append_new(jfiles, f);
    }
    json_object_set_new(root, "files", jfiles);

    errno = 0;
    int rc = json_dump_file(root, path, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    int err = errno;
    json_decref(root);
    if (rc != 0) {
        fs_error(FS_ERR_IO, "%s: cannot write the sidecar: %s", path, strerror(err ? err : EIO));
        return -1;
    }
    return 0;
}
