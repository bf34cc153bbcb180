/* Tests of the files fissure writes beside the maps: the JSON sidecar (io/sidecar.h), the OBJ mesh
 * (io/obj.h) and the engine targets' names and packed maps (io/target.h), each read back from disk. */
#define _GNU_SOURCE /* memmem */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/error.h"
#include "check.h"
#include "image/image.h"
#include "io/json.h"
#include "io/obj.h"
#include "io/output.h"
#include "io/sidecar.h"
#include "io/target.h"

static char tmpdir[] = "/tmp/fissure-test-io-XXXXXX";

static const char *tmp_path(const char *name)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    return path;
}

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap + 1);
    size_t got;
    while ((got = fread(buf + len, 1, cap - len, f)) > 0) {
        len += got;
        if (len == cap)
            buf = realloc(buf, (cap *= 2) + 1);
    }
    fclose(f);
    buf[len] = '\0';
    if (n)
        *n = len;
    return buf;
}

static bool str_is(fs_json *v, const char *s)
{
    const char *t = fs_json_text(v);
    return t && !strcmp(t, s);
}

/* A small image whose pixel k holds (k * step + c) for channel c, wrapped to the type. */
static void ramp(fs_image *img, int w, int h, int channels, fs_pixel_type type, int step)
{
    fs_image_alloc(img, w, h, channels, type);
    size_t n = (size_t)w * h * channels;
    for (size_t k = 0; k < n; k++) {
        if (type == FS_PIX_U8)
            ((uint8_t *)img->data)[k] = (uint8_t)(k * step);
        else
            ((uint16_t *)img->data)[k] = (uint16_t)(k * step * 257);
    }
}

/* The sidecar lists what it was given: preset, seed, statistics, per map its format, meaning and
 * tileability, the frames, and every file of the set; a name that is not UTF-8 writes nothing. */
static void test_sidecar(void)
{
    fs_config cfg = fs_config_default();
    snprintf(cfg.preset.name, sizeof cfg.preset.name, "unit");
    cfg.preset.seed = 42;
    cfg.domain.periodic_x = true;
    cfg.render.normal = FS_NORMAL_DIRECTX;
    fs_stats stats = {.nodes = 7, .elements = 9, .fractures = 3, .simulated_time = 2.5};
    fs_maps maps = {.height_min_cm = -0.5, .height_max_cm = 1.5, .crackdist_scale = 0.25};
    fs_image height, normal, preview;
    ramp(&height, 8, 4, 1, FS_PIX_U16, 1);
    ramp(&normal, 8, 4, 3, FS_PIX_U8, 1);
    ramp(&preview, 6, 6, 3, FS_PIX_U8, 1);
    fs_sidecar_map list[] = {
        {"height", "unit_height.png", &height, "linear", "height", NULL},
        {"normal", "unit_normal.png", &normal, "linear", "tangent-space normal", "Normal"},
        {"preview", "unit_preview.png", &preview, "srgb", NULL, NULL},
        {"cracks", "unit_cracks.json", NULL, "data", "crack graph", NULL},
    };
    const double time[2] = {1.25, 2.5}, hmin[2] = {-0.1, -0.5}, hmax[2] = {0.5, 1.5};
    const int64_t fractures[2] = {1, 3};
    fs_sidecar_frames frames = {2, "unit_frame_NNNN_KIND.png", time, fractures, hmin, hmax, list, 1};
    const char *files[] = {"unit_height.png", "unit_normal.png", "unit_preview.png", "unit_cracks.json"};
    const char *path = tmp_path("unit.json");
    CHECK(fs_sidecar_write(path, &cfg, "[preset]\nname = unit\n", &stats, &maps, "unreal", list, 4, &frames, files,
                           4, 1.0) == 0);

    fs_json *root = fs_json_read(path);
    CHECK_MSG(root != NULL, "%s does not parse as JSON", path);
    if (root) {
        CHECK(str_is(fs_json_get(root, "generator"), "fissure"));
        CHECK(fs_json_number(fs_json_get(root, "seed")) == 42);
        fs_json *preset = fs_json_get(root, "preset");
        CHECK(str_is(fs_json_get(preset, "name"), "unit"));
        const char *hash = fs_json_text(fs_json_get(preset, "hash"));
        CHECK(hash && !strncmp(hash, "fnv1a64:", 8) && strlen(hash) == 24);
        fs_json *st = fs_json_get(root, "stats");
        CHECK(fs_json_number(fs_json_get(st, "nodes")) == 7);
        CHECK(fs_json_number(fs_json_get(st, "elements")) == 9);
        CHECK(fs_json_number(fs_json_get(st, "fractures")) == 3);
        CHECK(fs_json_number(fs_json_get(st, "simulated_time")) == 2.5);
        CHECK(str_is(fs_json_get(root, "target"), "unreal"));
        CHECK(fs_json_size(fs_json_get(root, "parameters")) > 10);

        fs_json *jm = fs_json_get(root, "maps");
        CHECK(fs_json_size(jm) == 4);
        fs_json *h = fs_json_get(jm, "height");
        CHECK(str_is(fs_json_get(h, "file"), "unit_height.png"));
        CHECK(fs_json_number(fs_json_get(h, "bit_depth")) == 16);
        CHECK(fs_json_number(fs_json_get(h, "channels")) == 1);
        CHECK(fs_json_number(fs_json_get(h, "width")) == 8 && fs_json_number(fs_json_get(h, "height")) == 4);
        CHECK_NEAR(fs_json_number(fs_json_get(h, "height_min_cm")), -0.5, 1e-12);
        CHECK_NEAR(fs_json_number(fs_json_get(h, "height_scale_cm")), 2.0, 1e-12);
        /* the plane wraps in x only: its maps tile in u, not in v */
        fs_json *tile = fs_json_get(h, "tileable");
        CHECK(str_is(fs_json_get(h, "color_space"), "linear"));
        char *t = fs_json_dump(tile, (fs_json_format){0, 0});
        CHECK_MSG(t && !strcmp(t, "{\"u\":true,\"v\":false}"), "tileable %s", t ? t : "(null)");
        free(t);
        fs_json *n = fs_json_get(jm, "normal");
        CHECK(str_is(fs_json_get(n, "normal_convention"), "directx"));
        CHECK(str_is(fs_json_get(n, "usage"), "Normal"));
        CHECK(fs_json_number(fs_json_get(n, "bit_depth")) == 8 && fs_json_number(fs_json_get(n, "channels")) == 3);
        /* a perspective view never tiles */
        t = fs_json_dump(fs_json_get(fs_json_get(jm, "preview"), "tileable"), (fs_json_format){0, 0});
        CHECK_MSG(t && !strcmp(t, "{\"u\":false,\"v\":false}"), "preview tileable %s", t ? t : "(null)");
        free(t);
        CHECK(str_is(fs_json_get(fs_json_get(jm, "preview"), "png_color_chunk"), "sRGB"));
        fs_json *c = fs_json_get(jm, "cracks");
        CHECK(fs_json_get(c, "width") == NULL && str_is(fs_json_get(c, "file"), "unit_cracks.json"));

        fs_json *jf = fs_json_get(root, "frames");
        CHECK(fs_json_number(fs_json_get(jf, "count")) == 2);
        fs_json *fh = fs_json_get(fs_json_get(jf, "maps"), "height");
        CHECK(fh && fs_json_get(fh, "height_min_cm") == NULL);
        fs_json *f2 = fs_json_at(fs_json_get(jf, "frames"), 1);
        CHECK(fs_json_number(fs_json_get(f2, "frame")) == 2);
        CHECK(fs_json_number(fs_json_get(f2, "time")) == 2.5);
        CHECK(fs_json_number(fs_json_get(f2, "fractures")) == 3);
        CHECK_NEAR(fs_json_number(fs_json_get(f2, "height_max_cm")), 1.5, 1e-12);

        fs_json *jfiles = fs_json_get(root, "files");
        CHECK(fs_json_size(jfiles) == 4);
        for (size_t i = 0; i < 4; i++)
            CHECK_MSG(str_is(fs_json_at(jfiles, i), files[i]), "files[%zu]", i);
        fs_json_free(root);
    }

    const char *bad[] = {"unit_height.png", "unit_\xff.png"};
    const char *path2 = tmp_path("bad.json");
    fs_error_clear();
    CHECK(fs_sidecar_write(path2, &cfg, NULL, &stats, &maps, "generic", list, 1, NULL, bad, 2, 1.0) == -1);
    CHECK(fs_error_domain() == FS_ERR_CANTCREAT);
    CHECK(access(path2, F_OK) != 0);
    fs_error_clear();
    fs_image_free(&height);
    fs_image_free(&normal);
    fs_image_free(&preview);
}

/* A square of two layer triangles and one wall triangle, written and parsed back. */
static void test_obj(void)
{
    double pos[] = {0, 0, 0, 10, 0, 0, 10, 10, 0, 0, 10, 0, 0, 0, -0.125};
    float uv[] = {0, 0, 1, 0, 1, 1, 0, 1};
    float normal[] = {0, 0, 1, 0, -1, 0};
    int32_t corner[] = {
        0, 0, 0, 1, 1, 0, 2, 2, 0, /* layer */
        0, 0, 1, 4, 0, 1, 1, 1, 1, /* wall */
        0, 0, 0, 2, 2, 0, 3, 3, 0, /* layer */
    };
    uint8_t wall[] = {0, 1, 0};
    fs_lifted_mesh m = {5, pos, 4, uv, 2, normal, 3, corner, wall, 1e-4};
    const char *path = tmp_path("unit.obj");
    CHECK(fs_obj_write(path, &m, "unit", "made by test_io", "unit.mtl") == 0);
    char *text = slurp(path, NULL);
    CHECK(text != NULL);
    if (!text)
        return;
    CHECK(!strncmp(text, "# made by test_io\n", 18));
    CHECK(strstr(text, "# 5 positions, 4 texture vertices, 2 normals, 3 triangles (1 in walls)\n") != NULL);
    CHECK(strstr(text, "\nmtllib unit.mtl\n") != NULL);
    CHECK(strstr(text, "\no unit\nusemtl unit\n") != NULL);

    int nv = 0, nvt = 0, nvn = 0, nf = 0, bad = 0;
    int group = -1, faces_in[2] = {0, 0};
    char *save = NULL;
    for (char *line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        double a, b, c;
        if (!strncmp(line, "v ", 2)) {
            CHECK(sscanf(line + 2, "%lf %lf %lf", &a, &b, &c) == 3);
            bad += nv < 5 && (fabs(a - pos[3 * nv]) > 1e-6 || fabs(b - pos[3 * nv + 1]) > 1e-6 ||
                              fabs(c - pos[3 * nv + 2]) > 1e-6);
            nv++;
        } else if (!strncmp(line, "vt ", 3)) {
            CHECK(sscanf(line + 3, "%lf %lf", &a, &b) == 2);
            bad += nvt < 4 && (fabs(a - uv[2 * nvt]) > 1e-8 || fabs(b - uv[2 * nvt + 1]) > 1e-8);
            nvt++;
        } else if (!strncmp(line, "vn ", 3)) {
            CHECK(sscanf(line + 3, "%lf %lf %lf", &a, &b, &c) == 3);
            bad += nvn < 2 && fabs(a * a + b * b + c * c - 1.0) > 1e-5;
            nvn++;
        } else if (!strcmp(line, "g layer")) {
            group = 0;
        } else if (!strcmp(line, "g walls")) {
            group = 1;
        } else if (line[0] == 'f') {
            int k[9];
            CHECK(sscanf(line, "f %d/%d/%d %d/%d/%d %d/%d/%d", &k[0], &k[1], &k[2], &k[3], &k[4], &k[5], &k[6],
                         &k[7], &k[8]) == 9);
            CHECK(group >= 0);
            if (group >= 0)
                faces_in[group]++;
            /* the faces of each group come in the mesh's order, indices from 1 */
            int t = group == 1 ? 1 : faces_in[0] == 1 ? 0 : 2;
            for (int q = 0; q < 9; q++)
                bad += k[q] != corner[9 * t + q] + 1;
            nf++;
        }
    }
    CHECK(bad == 0);
    CHECK(nv == 5 && nvt == 4 && nvn == 2 && nf == 3);
    CHECK(faces_in[0] == 2 && faces_in[1] == 1);
    free(text);

    fs_error_clear();
    CHECK(fs_obj_write("/nonexistent-dir/unit.obj", &m, "unit", NULL, NULL) == -1);
    CHECK(fs_error_domain() == FS_ERR_IO);
    fs_error_clear();
}

static void test_target_words(void)
{
    for (int t = 0; t < FS_TARGET_COUNT; t++) {
        fs_target back;
        CHECK(fs_target_parse(fs_target_name((fs_target)t), &back) == 0 && back == (fs_target)t);
    }
    fs_target back;
    CHECK(fs_target_parse("unity", &back) == -1);
    CHECK(!fs_target_fixes_normal(FS_TARGET_GENERIC));
    CHECK(fs_target_fixes_normal(FS_TARGET_GLTF) && fs_target_normal(FS_TARGET_GLTF) == FS_NORMAL_OPENGL);
    CHECK(fs_target_normal(FS_TARGET_UNREAL) == FS_NORMAL_DIRECTX);
    CHECK(fs_target_normal(FS_TARGET_UNITY_HDRP) == FS_NORMAL_OPENGL);
    CHECK(fs_target_normal(FS_TARGET_BLENDER) == FS_NORMAL_OPENGL);
}

static bool has_srgb_chunk(const char *path)
{
    size_t n;
    char *data = slurp(path, &n);
    bool found = data && memmem(data, n, "sRGB", 4) != NULL;
    free(data);
    return found;
}

/* Writes kinds for target t into a fresh set in dir and commits it. */
static int write_target(const char *dir, fs_target t, const fs_target_inputs *in, fs_target_output *w)
{
    static const char *kinds[] = {"basecolor", "normal", "height", "crackmask", "occlusion"};
    fs_output *out = fs_output_begin(dir);
    if (!out)
        return -1;
    if (fs_target_write(out, t, "unit", kinds, 5, in, w) < 0) {
        fs_output_abort(out);
        return -1;
    }
    return fs_output_commit(out);
}

/* Each engine's file names and its packed occlusion map, read back from the PNGs. */
static void test_target_files(void)
{
    fs_maps maps = {0};
    ramp(&maps.basecolor, 4, 2, 3, FS_PIX_U8, 5);
    ramp(&maps.normal, 4, 2, 3, FS_PIX_U8, 7);
    ramp(&maps.height, 4, 2, 1, FS_PIX_U16, 3);
    ramp(&maps.crackmask, 4, 2, 1, FS_PIX_U8, 31);
    fs_image ao;
    ramp(&ao, 4, 2, 1, FS_PIX_U8, 11);
    fs_target_inputs in = {&maps, &maps.height, "png", NULL, &ao, 0.25, FS_NORMAL_OPENGL, NULL};
    const uint8_t *a = ao.data, *mask = maps.crackmask.data;
    const uint8_t rough = 64, smooth = 191; /* 0.25 and 0.75 of 255, rounded */

    struct {
        fs_target t;
        const char *sub, *files[6];
    } cases[] = {
        {FS_TARGET_GENERIC, "generic",
         {"unit_basecolor.png", "unit_normal.png", "unit_height.png", "unit_crackmask.png", "unit_occlusion.png"}},
        {FS_TARGET_GLTF, "gltf",
         {"unit_baseColor.png", "unit_normal.png", "unit_height.png", "unit_crackmask.png",
          "unit_occlusionRoughnessMetallic.png"}},
        {FS_TARGET_UNREAL, "unreal",
         {"T_unit_BC.png", "T_unit_N.png", "T_unit_H.png", "T_unit_CrackMask.png", "T_unit_ORM.png"}},
        {FS_TARGET_UNITY_HDRP, "unity",
         {"unit_BaseColor.png", "unit_Normal.png", "unit_Height.png", "unit_crackmask.png", "unit_MaskMap.png"}},
        {FS_TARGET_BLENDER, "blender",
         {"unit_basecolor.png", "unit_normal.png", "unit_height.png", "unit_crackmask.png", "unit_ao.png",
          "unit_roughness.png"}},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        char dir[512], path[600];
        snprintf(dir, sizeof dir, "%s/%s", tmpdir, cases[c].sub);
        fs_target_output w;
        CHECK_MSG(write_target(dir, cases[c].t, &in, &w) == 0, "target %s", cases[c].sub);
        int n_expected = cases[c].files[5] ? 6 : 5;
        CHECK_MSG(w.n == n_expected, "target %s wrote %d files", cases[c].sub, w.n);
        for (int i = 0; i < n_expected && i < w.n; i++) {
            CHECK_MSG(!strcmp(w.file[i], cases[c].files[i]), "target %s file %d: %s", cases[c].sub, i, w.file[i]);
            snprintf(path, sizeof path, "%s/%s", dir, cases[c].files[i]);
            CHECK_MSG(access(path, F_OK) == 0, "%s missing", path);
            /* colour maps carry an sRGB chunk, data maps none */
            CHECK_MSG(has_srgb_chunk(path) == (i == 0), "%s sRGB chunk", path);
        }
        /* the normal map is written as given; the packed occlusion map holds what the engine reads */
        snprintf(path, sizeof path, "%s/%s", dir, cases[c].files[4]);
        fs_image img = {0};
        CHECK(fs_image_read(path, &img) == 0);
        const uint8_t *p = img.data;
        int bad = 0;
        for (int k = 0; p && k < 8; k++) {
            switch (cases[c].t) {
            case FS_TARGET_GLTF:
            case FS_TARGET_UNREAL:
                bad += img.channels != 3 || p[3 * k] != a[k] || p[3 * k + 1] != rough || p[3 * k + 2] != 0;
                break;
            case FS_TARGET_UNITY_HDRP:
                bad += img.channels != 4 || p[4 * k] != 0 || p[4 * k + 1] != a[k] || p[4 * k + 2] != mask[k] ||
                       p[4 * k + 3] != smooth;
                break;
            default:
                bad += img.channels != 1 || p[k] != a[k];
            }
        }
        CHECK_MSG(bad == 0, "target %s: %d packed pixels wrong", cases[c].sub, bad);
        fs_image_free(&img);
        if (cases[c].t == FS_TARGET_BLENDER) {
            snprintf(path, sizeof path, "%s/unit_roughness.png", dir);
            CHECK(fs_image_read(path, &img) == 0);
            CHECK(img.channels == 1 && img.data && ((uint8_t *)img.data)[5] == rough);
            fs_image_free(&img);
        }
        fs_target_output_free(&w);
    }
    fs_image_free(&ao);
    fs_maps_free(&maps);
}

static void remove_tree(const char *dir)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
}

int main(void)
{
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 99;
    }
    RUN(test_sidecar);
    RUN(test_obj);
    RUN(test_target_words);
    RUN(test_target_files);
    remove_tree(tmpdir);
    return check_finish();
}
