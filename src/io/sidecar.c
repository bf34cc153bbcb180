/* The JSON sidecar: what was run (resolved preset, seed), what happened (stats) and what each map holds. */
#include "io/sidecar.h"

#include "config.h"

#include <errno.h>
#include <stdbool.h>
#include <string.h>

#include "base/error.h"
#include "io/json.h"
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
    fs_json *params = ctx;
    fs_json *sec = fs_json_get(params, section);
    if (!sec) {
        sec = fs_json_object();
        fs_json_set(params, section, sec);
    }
    fs_json_set(sec, key, fs_json_string(value));
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

static fs_json *map_entry(const fs_sidecar_map *m, const fs_config *cfg, const fs_maps *maps)
{
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    fs_json *e = fs_json_object();
    fs_json_set(e, "file", fs_json_string(m->file));
    if (m->usage)
        fs_json_set(e, "usage", fs_json_string(m->usage));
    if (m->channels)
        fs_json_set(e, "channels_meaning", fs_json_string(m->channels));
    if (!m->image)
        return e;
    fs_json_set(e, "color_space", fs_json_string(m->color_space));
    if (m->image->type != FS_PIX_F32)
        fs_json_set(e, "png_color_chunk",
                            fs_json_string(!strcmp(m->color_space, "srgb") ? "sRGB" : "none (raw values)"));
    fs_json_set(e, "bit_depth", fs_json_integer(bit_depth(m->image)));
    fs_json_set(e, "sample_format", fs_json_string(m->image->type == FS_PIX_F32 ? "float" : "unsigned"));
    fs_json_set(e, "channels", fs_json_integer(m->image->channels));
    fs_json_set(e, "width", fs_json_integer(m->image->width));
    fs_json_set(e, "height", fs_json_integer(m->image->height));
    /* a perspective view of the object never tiles, whatever the domain does */
    bool texture_space = strcmp(m->kind, "preview") != 0;
    fs_json *tile = fs_json_object();
    fs_json_set(tile, "u", fs_json_bool(texture_space && fs_domain_wraps_u(&d)));
    fs_json_set(tile, "v", fs_json_bool(texture_space && fs_domain_wraps_v(&d)));
    fs_json_set(e, "tileable", tile);
    if (!strcmp(m->kind, "height")) {
        fs_json_set(e, "height_min_cm", fs_json_real(maps->height_min_cm));
        fs_json_set(e, "height_max_cm", fs_json_real(maps->height_max_cm));
        fs_json_set(e, "height_scale_cm", fs_json_real(maps->height_max_cm - maps->height_min_cm));
        fs_json_set(e, "encoding", fs_json_string(m->image->type == FS_PIX_F32
                                                           ? "height in cm"
                                                           : "0 = height_min_cm, full scale = height_max_cm, linear"));
    } else if (!strcmp(m->kind, "normal")) {
        fs_json_set(e, "normal_convention",
                            fs_json_string(cfg->render.normal == FS_NORMAL_DIRECTX ? "directx" : "opengl"));
        fs_json_set(e, "height_scale", fs_json_real(cfg->render.height_scale));
    } else if (!strcmp(m->kind, "crackdist")) {
        fs_json_set(e, "units_per_pixel", fs_json_real(maps->crackdist_scale));
    } else if (!strcmp(m->kind, "cellid")) {
        fs_json_set(e, "encoding", fs_json_string("fragment id, 0 = crack"));
    } else if (!strcmp(m->kind, "crackmask")) {
        fs_json_set(e, "encoding", fs_json_string("crack coverage, 255 = crack"));
    } else if (!strcmp(m->kind, "occlusion") || !strcmp(m->kind, "roughness")) {
        fs_json_set(e, "roughness", fs_json_real(cfg->render.roughness));
    }
    return e;
}

int fs_sidecar_write(const char *path, const fs_config *cfg, const char *preset_text, const fs_stats *stats,
                     const fs_maps *maps, const char *target, const fs_sidecar_map *list, int n_maps,
                     const fs_sidecar_frames *frames, const char *const *files, int n_files, double wall_seconds)
{
    fs_json *root = fs_json_object();
    fs_json_set(root, "generator", fs_json_string("fissure"));
    fs_json_set(root, "version", fs_json_string(PACKAGE_VERSION));

    fs_json *preset = fs_json_object();
    fs_json_set(preset, "name", fs_json_string(cfg->preset.name));
    if (preset_text) {
        char hash[32];
        snprintf(hash, sizeof hash, "fnv1a64:%016llx", (unsigned long long)fnv1a64(preset_text));
        fs_json_set(preset, "hash", fs_json_string(hash));
    }
    fs_json_set(root, "preset", preset);
    fs_json_set(root, "seed", fs_json_integer((int64_t)cfg->preset.seed));

    fs_json *params = fs_json_object();
    fs_preset_visit(cfg, visit_param, params);
    fs_json_set(root, "parameters", params);

    fs_json *st = fs_json_object();
    fs_json_set(st, "nodes", fs_json_integer(stats->nodes));
    fs_json_set(st, "elements", fs_json_integer(stats->elements));
    fs_json_set(st, "fractures", fs_json_integer(stats->fractures));
    fs_json_set(st, "simulated_time", fs_json_real(stats->simulated_time));
    fs_json_set(st, "wall_seconds", fs_json_real(wall_seconds));
    fs_json_set(root, "stats", st);

    fs_json_set(root, "target", fs_json_string(target));
    fs_json *jm = fs_json_object();
    for (int i = 0; i < n_maps; i++)
        fs_json_set(jm, list[i].kind, map_entry(&list[i], cfg, maps));
    fs_json_set(root, "maps", jm);

    if (frames) {
        fs_json *jf = fs_json_object();
        fs_json_set(jf, "count", fs_json_integer(frames->count));
        fs_json_set(jf, "file_pattern", fs_json_string(frames->file_pattern));
        fs_json *kinds = fs_json_object();
        for (int i = 0; i < frames->n_maps; i++) {
            fs_json *e = map_entry(&frames->map[i], cfg, maps);
            /* each frame's height map has its own range, listed per frame below */
            fs_json_del(e, "height_min_cm");
            fs_json_del(e, "height_max_cm");
            fs_json_del(e, "height_scale_cm");
            fs_json_set(kinds, frames->map[i].kind, e);
        }
        fs_json_set(jf, "maps", kinds);
        fs_json *list_f = fs_json_array();
        for (int32_t k = 0; k < frames->count; k++) {
            fs_json *f = fs_json_object();
            fs_json_set(f, "frame", fs_json_integer(k + 1));
            fs_json_set(f, "time", fs_json_real(frames->time[k]));
            fs_json_set(f, "fractures", fs_json_integer(frames->fractures[k]));
            fs_json_set(f, "height_min_cm", fs_json_real(frames->height_min_cm[k]));
            fs_json_set(f, "height_max_cm", fs_json_real(frames->height_max_cm[k]));
            fs_json_append(list_f, f);
        }
        fs_json_set(jf, "frames", list_f);
        fs_json_set(root, "frames", jf);
    }

    fs_json *jfiles = fs_json_array();
    for (int i = 0; i < n_files; i++) {
        if (!fs_json_valid_utf8(files[i])) {
            fs_json_free(jfiles);
            fs_json_free(root);
            fs_error(FS_ERR_CANTCREAT, "%s: the sidecar cannot list a file name that is not UTF-8", files[i]);
            return -1;
        }
        fs_json_append(jfiles, fs_json_string(files[i]));
    }
    fs_json_set(root, "files", jfiles);

    errno = 0;
    int rc = fs_json_write(root, path, (fs_json_format){2, 10});
    int err = errno;
    fs_json_free(root);
    if (rc != 0) {
        fs_error(FS_ERR_IO, "%s: cannot write the sidecar: %s", path, strerror(err ? err : EIO));
        return -1;
    }
    return 0;
}
