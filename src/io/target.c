/* Engine targets: the table of file names, packing, conventions and colour tags per engine (see target.h). */
#include "io/target.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base/error.h"
#include "io/cracks.h"

static const char *const target_names[FS_TARGET_COUNT] = {"generic", "gltf", "unreal", "unity-hdrp", "blender"};

const char *fs_target_name(fs_target t)
{
    return t >= 0 && t < FS_TARGET_COUNT ? target_names[t] : "?";
}

int fs_target_parse(const char *word, fs_target *out)
{
    for (int t = 0; t < FS_TARGET_COUNT; t++)
        if (!strcmp(word, target_names[t])) {
            *out = (fs_target)t;
            return 0;
        }
    return -1;
}

bool fs_target_fixes_normal(fs_target t)
{
    return t != FS_TARGET_GENERIC;
}

fs_normal_convention fs_target_normal(fs_target t)
{
    return t == FS_TARGET_UNREAL ? FS_NORMAL_DIRECTX : FS_NORMAL_OPENGL;
}

/* One row of the table: a map kind as one engine names and uses it. %s is the output name. */
typedef struct {
    const char *kind;
    fs_target target;
    const char *pattern;     /* file name, without extension */
    const char *usage;
} file_rule;

/* design: names follow what each engine's import tooling recognises: glTF sample assets'
 * camelCase texture roles; Unreal's T_ prefix with BC / N / ORM / H suffixes (Epic's and the
 * community style guide's asset naming); HDRP Lit's BaseColor / Normal / MaskMap / Height slots;
 * and Blender's Node Wrangler "Principled texture setup" tags (basecolor, normal, height, ao,
 * roughness), which also sets Non-Color on the data maps it recognises. */
static const file_rule rules[] = {
    {"basecolor", FS_TARGET_GLTF, "%s_baseColor", "material.pbrMetallicRoughness.baseColorTexture"},
    {"normal", FS_TARGET_GLTF, "%s_normal", "material.normalTexture (glTF normal maps are +Y up)"},
    {"occlusion", FS_TARGET_GLTF, "%s_occlusionRoughnessMetallic",
     "material.occlusionTexture (R) and material.pbrMetallicRoughness.metallicRoughnessTexture (G, B)"},
    {"basecolor", FS_TARGET_UNREAL, "T_%s_BC", "material Base Color; texture sRGB on"},
    {"normal", FS_TARGET_UNREAL, "T_%s_N", "material Normal; compression Normalmap (DirectX green, as imported)"},
    {"occlusion", FS_TARGET_UNREAL, "T_%s_ORM",
     "material Ambient Occlusion (R), Roughness (G), Metallic (B); compression Masks, sRGB off"},
    {"height", FS_TARGET_UNREAL, "T_%s_H", "displacement or parallax height; sRGB off"},
    {"crackmask", FS_TARGET_UNREAL, "T_%s_CrackMask", "mask for material blends; sRGB off"},
    {"crackdist", FS_TARGET_UNREAL, "T_%s_CrackDist", "distance field for material effects; sRGB off"},
    {"cellid", FS_TARGET_UNREAL, "T_%s_CellID", "per-fragment id; sRGB off, nearest filtering"},
    {"basecolor", FS_TARGET_UNITY_HDRP, "%s_BaseColor", "Lit material Base Map (sRGB)"},
    {"normal", FS_TARGET_UNITY_HDRP, "%s_Normal", "Lit material Normal Map; texture type Normal map"},
    {"occlusion", FS_TARGET_UNITY_HDRP, "%s_MaskMap", "Lit material Mask Map; sRGB (Color Texture) off"},
    {"height", FS_TARGET_UNITY_HDRP, "%s_Height", "Lit material Height Map; sRGB (Color Texture) off"},
    {"basecolor", FS_TARGET_BLENDER, "%s_basecolor", "Principled BSDF Base Color; colour space sRGB"},
    {"normal", FS_TARGET_BLENDER, "%s_normal", "Normal Map node, tangent space; colour space Non-Color"},
    {"occlusion", FS_TARGET_BLENDER, "%s_ao", "ambient occlusion (multiply into Base Color); Non-Color"},
    {"roughness", FS_TARGET_BLENDER, "%s_roughness", "Principled BSDF Roughness; colour space Non-Color"},
    {"height", FS_TARGET_BLENDER, "%s_height", "Displacement node Height; colour space Non-Color"},
};

static const file_rule *find_rule(fs_target t, const char *kind)
{
    for (size_t i = 0; i < sizeof rules / sizeof rules[0]; i++)
        if (rules[i].target == t && !strcmp(rules[i].kind, kind))
            return &rules[i];
    return NULL;
}

/* Colour space of a kind (what the sidecar has always said), and whether the PNG gets an sRGB chunk. */
static const char *kind_color_space(const char *kind)
{
    if (!strcmp(kind, "basecolor") || !strcmp(kind, "preview"))
        return "srgb";
    if (!strcmp(kind, "normal") || !strcmp(kind, "cellid"))
        return "data";
    return "linear";
}

static const char *kind_channels(const char *kind, fs_target t, const fs_target_inputs *in, bool exr)
{
    if (!strcmp(kind, "height"))
        return exr ? "grey: height in cm" : "grey: height, 0 = height_min_cm, 65535 = height_max_cm, linear";
    if (!strcmp(kind, "normal"))
        return in->normal == FS_NORMAL_DIRECTX
                   ? "R: +X (right), G: -Y (DirectX: 255 - the OpenGL green), B: +Z; n * 0.5 + 0.5"
                   : "R: +X (right), G: +Y (up, OpenGL), B: +Z; n * 0.5 + 0.5";
    if (!strcmp(kind, "basecolor"))
        return "RGB: base colour, sRGB";
    if (!strcmp(kind, "crackmask"))
        return "grey: crack coverage, 255 = crack";
    if (!strcmp(kind, "crackdist"))
        return "grey: distance to the nearest crack in pixels times units_per_pixel";
    if (!strcmp(kind, "cellid"))
        return "grey: fragment id, 0 = crack";
    if (!strcmp(kind, "preview"))
        return "RGB: lit view of the result, sRGB";
    if (!strcmp(kind, "roughness"))
        return "grey: roughness ([render] roughness)";
    if (!strcmp(kind, "occlusion")) {
        switch (t) {
        case FS_TARGET_GLTF:
        case FS_TARGET_UNREAL:
            return "R: ambient occlusion (255 = open; crack depth below the blurred height), "
                   "G: roughness ([render] roughness), B: metallic = 0";
        case FS_TARGET_UNITY_HDRP:
            return "R: metallic = 0, G: ambient occlusion (255 = open; crack depth below the blurred height), "
                   "B: detail mask = crack mask (255 = crack), A: smoothness = 1 - [render] roughness";
        default:
            return "grey: ambient occlusion, 255 = open; crack depth below the blurred height";
        }
    }
    return NULL;
}

static uint8_t unit_byte(double x)
{
    x = x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x;
    return (uint8_t)floor(x * 255.0 + 0.5);
}

/* Packs the occlusion-carrying image of target t into img (allocated). */
static void pack_occlusion(fs_target t, const fs_target_inputs *in, fs_image *img)
{
    const fs_image *ao = in->occlusion;
    const size_t n = (size_t)ao->width * (size_t)ao->height;
    const uint8_t *a = ao->data;
    const uint8_t rough = unit_byte(in->roughness), smooth = unit_byte(1.0 - in->roughness);
    if (t == FS_TARGET_GLTF || t == FS_TARGET_UNREAL) {
        fs_image_alloc(img, ao->width, ao->height, 3, FS_PIX_U8);
        uint8_t *p = img->data;
        for (size_t k = 0; k < n; k++) {
            p[3 * k] = a[k];
            p[3 * k + 1] = rough;
            p[3 * k + 2] = 0;
        }
    } else if (t == FS_TARGET_UNITY_HDRP) {
        fs_image_alloc(img, ao->width, ao->height, 4, FS_PIX_U8);
        uint8_t *p = img->data;
        const uint8_t *mask = in->maps->crackmask.data;
        for (size_t k = 0; k < n; k++) {
            p[4 * k] = 0;
            p[4 * k + 1] = a[k];
            p[4 * k + 2] = mask[k];
            p[4 * k + 3] = smooth;
        }
    } else {
        fs_image_alloc(img, ao->width, ao->height, 1, FS_PIX_U8);
        memcpy(img->data, a, n);
    }
}

static const fs_image *kind_image(const char *kind, const fs_target_inputs *in)
{
    const fs_maps *m = in->maps;
    if (!strcmp(kind, "height"))
        return in->height;
    if (!strcmp(kind, "normal"))
        return &m->normal;
    if (!strcmp(kind, "basecolor"))
        return &m->basecolor;
    if (!strcmp(kind, "crackmask"))
        return &m->crackmask;
    if (!strcmp(kind, "crackdist"))
        return &m->crackdist;
    if (!strcmp(kind, "cellid"))
        return &m->cellid;
    if (!strcmp(kind, "preview"))
        return in->preview;
    return NULL;
}

/* Reserves the next entry of w for file `file` of `kind`; returns its index. */
static int add_entry(fs_target_output *w, const char *kind, const char *usage, const char *channels,
                     const char *color_space, const char *pattern, const char *name, const char *ext)
{
    FS_ASSERT(w->n < FS_TARGET_MAX_FILES);
    int i = w->n++;
    char stem[480];
    snprintf(stem, sizeof stem, pattern, name);
    snprintf(w->file[i], sizeof w->file[i], "%s.%s", stem, ext);
    w->map[i] = (fs_sidecar_map){kind, w->file[i], NULL, color_space, channels, usage};
    return i;
}

static int write_image(fs_output *out, fs_target_output *w, int i, const fs_image *img)
{
    w->map[i].image = img;
    fs_image_tag tag = !strcmp(w->map[i].color_space, "srgb") ? FS_IMAGE_SRGB : FS_IMAGE_UNTAGGED;
    return fs_image_write_tagged(fs_output_stage(out, w->file[i]), img, tag);
}

/* Writes one map kind (one or two files). */
static int write_kind(fs_output *out, fs_target t, const char *name, const char *kind, const fs_target_inputs *in,
                      fs_target_output *w)
{
    if (!strcmp(kind, "cracks")) {
        int j = add_entry(w, "cracks", NULL,
                          "crack graph: nodes (junctions with degree, ends), cracks (centre line polylines in "
                          "texture space, sides), fragments and their adjacency",
                          "data", "%s_cracks", name, "json");
        int s = add_entry(w, "cracks_svg", NULL, "crack graph drawn over the map, in pixels", "data", "%s_cracks",
                          name, "svg");
        if (fs_cracks_write_json(fs_output_stage(out, w->file[j]), in->cracks) < 0)
            return -1;
        return fs_cracks_write_svg(fs_output_stage(out, w->file[s]), in->cracks);
    }
    const file_rule *rule = find_rule(t, kind);
    const char *pattern = rule ? rule->pattern : NULL;
    char generic[64];
    if (!pattern) {
        snprintf(generic, sizeof generic, "%%s_%s", kind);
        pattern = generic;
    }
    const char *usage = rule ? rule->usage : NULL;
    bool exr = !strcmp(kind, "height") && !strcmp(in->height_ext, "exr");
    const char *channels = kind_channels(kind, t, in, exr);
    if (!strcmp(kind, "occlusion")) {
        int i = add_entry(w, kind, usage, channels, "linear", pattern, name, "png");
        pack_occlusion(t, in, &w->packed[i]);
        if (write_image(out, w, i, &w->packed[i]) < 0)
            return -1;
        if (t != FS_TARGET_BLENDER)
            return 0;
        /* Blender takes roughness as a map of its own. */
        const file_rule *r = find_rule(t, "roughness");
        int k = add_entry(w, "roughness", r->usage, kind_channels("roughness", t, in, false), "linear", r->pattern,
                          name, "png");
        fs_image_alloc(&w->packed[k], in->occlusion->width, in->occlusion->height, 1, FS_PIX_U8);
        memset(w->packed[k].data, unit_byte(in->roughness), fs_image_bytes(&w->packed[k]));
        return write_image(out, w, k, &w->packed[k]);
    }
    const fs_image *img = kind_image(kind, in);
    if (!img) {
        fs_error(FS_ERR_INTERNAL, "--target %s: no image for map kind '%s'", fs_target_name(t), kind);
        return -1;
    }
    int i = add_entry(w, kind, usage, channels, kind_color_space(kind), pattern, name, exr ? "exr" : "png");
    return write_image(out, w, i, img);
}

int fs_target_write(fs_output *out, fs_target t, const char *name, const char *const *kinds, int n_kinds,
                    const fs_target_inputs *in, fs_target_output *written)
{
    memset(written, 0, sizeof *written);
    for (int i = 0; i < n_kinds; i++)
        if (write_kind(out, t, name, kinds[i], in, written) < 0)
            return -1;
    return 0;
}

void fs_target_output_free(fs_target_output *w)
{
    for (int i = 0; i < FS_TARGET_MAX_FILES; i++)
        fs_image_free(&w->packed[i]);
}
