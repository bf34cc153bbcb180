/* fissure: command-line entry point — options, preset loading, the run, and writing the maps. */
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "base/error.h"
#include "base/log.h"
#include "base/threads.h"
#include "cli/cli.h"
#include "cli/jobs.h"
#include "config.h"
#include "io/asset.h"
#include "io/output.h"
#include "io/preset.h"
#include "io/sidecar.h"
#include "io/target.h"
#include "render/crackgraph.h"
#include "render/occlusion.h"
#include "render/render.h"
#include "sim/sim.h"

enum {
    MAP_HEIGHT, MAP_NORMAL, MAP_BASECOLOR, MAP_CRACKMASK, MAP_CRACKDIST, MAP_CELLID, MAP_PREVIEW, MAP_OCCLUSION,
    MAP_CRACKS, MAP_COUNT
};
/* Map kinds; io/target.h names, packs and tags their files per engine. */
static const char *const map_names[MAP_COUNT] = {"height", "normal", "basecolor", "crackmask", "crackdist", "cellid",
                                                 "preview", "occlusion", "cracks"};

typedef struct {
    const char *output_dir;
    const char *name;
    bool have_seed;
    uint64_t seed;
    bool have_size;
    int width, height;
    char **sets;
    int n_sets;
    bool maps[MAP_COUNT];
    bool exr;
    bool have_normal;
    fs_normal_convention normal;
    bool list_presets, dump_preset;
    fs_target target;      /* --target: the engine the maps are named, packed and oriented for */
    bool have_target;      /* --target was given (--asset accepts only gltf) */
    const char *mesh_path; /* --mesh FILE: the lifted 3-D layer as Wavefront OBJ, or NULL */
    const char *asset_path; /* --asset FILE: the layer and its material as glTF (.gltf or .glb), or NULL */
    bool have_maps;        /* --maps was given (it also picks the frames' maps) */
    int32_t frames;        /* --frames N: time-lapse frames, 0 for none */
    const char *job;       /* --job FILE:N: run job N of a jobs file (cli/jobs.h), or NULL */
    const char *list_jobs; /* --list-jobs FILE */
} options;

enum {
    OPT_SIZE = 256, OPT_SET, OPT_MAPS, OPT_FORMAT, OPT_NORMAL, OPT_LIST, OPT_DUMP, OPT_MESH, OPT_TARGET, OPT_FRAMES,
    OPT_ASSET, OPT_JOB, OPT_LIST_JOBS, OPT_PROGRESS
};

/* Most time-lapse frames one run writes. */
#define MAX_FRAMES 10000

static const struct option long_options[] = {
    {"output", required_argument, NULL, 'o'},
    {"name", required_argument, NULL, 'n'},
    {"seed", required_argument, NULL, 's'},
    {"size", required_argument, NULL, OPT_SIZE},
    {"set", required_argument, NULL, OPT_SET},
    {"maps", required_argument, NULL, OPT_MAPS},
    {"format", required_argument, NULL, OPT_FORMAT},
    {"normal", required_argument, NULL, OPT_NORMAL},
    {"target", required_argument, NULL, OPT_TARGET},
    {"quiet", no_argument, NULL, 'q'},
    {"verbose", no_argument, NULL, 'v'},
    {"list-presets", no_argument, NULL, OPT_LIST},
    {"dump-preset", no_argument, NULL, OPT_DUMP},
    {"mesh", required_argument, NULL, OPT_MESH},
    {"asset", required_argument, NULL, OPT_ASSET},
    {"job", required_argument, NULL, OPT_JOB},
    {"list-jobs", required_argument, NULL, OPT_LIST_JOBS},
    {"progress", required_argument, NULL, OPT_PROGRESS},
    {"frames", required_argument, NULL, OPT_FRAMES},
    {"threads", required_argument, NULL, 'j'},
    {"help", no_argument, NULL, 'h'},
    {"version", no_argument, NULL, 'V'},
    {NULL, 0, NULL, 0},
};

static void print_help(FILE *out)
{
    fputs("Usage: fissure [OPTION]... PRESET\n"
          "       fissure [OPTION]... --job FILE:N\n"
          "       fissure diff [OPTION]... A B\n"
          "Grow a crack pattern by simulation and render it into texture maps.\n"
          "PRESET is a preset file, or the name of one found on the preset path.\n"
          "\n"
          "  -o, --output DIR        write the maps into DIR (default: the current directory)\n"
          "  -n, --name NAME         file name prefix of the maps (default: the preset's name)\n"
          "  -s, --seed N            random seed (overrides [preset] seed)\n"
          "      --size WxH          map size in pixels (overrides [render] size)\n"
          "      --set SECTION.KEY=VALUE\n"
          "                          override one preset key (repeatable)\n"
          "      --maps LIST         comma-separated maps to write: height, normal, basecolor,\n"
          "                          crackmask, crackdist, cellid, preview, occlusion, cracks\n"
          "                          (crack graph JSON and SVG), or all (default: all but preview)\n"
          "      --format png|exr    height map as 16-bit PNG (default) or float EXR in cm\n"
          "      --normal opengl|directx\n"
          "                          normal map convention (default: opengl, +Y up)\n"
          "      --target ENGINE     name, pack and orient the maps for generic (default), gltf,\n"
          "                          unreal, unity-hdrp or blender\n"
          "      --mesh FILE         also write the cracked 3-D layer to FILE as Wavefront OBJ, with its\n"
          "                          material (the maps bound) in FILE.mtl; {name} in FILE stands for\n"
          "                          the output name (as in --asset)\n"
          "      --asset FILE        also write the layer and a PBR material binding the maps as a glTF\n"
          "                          2.0 asset: FILE.gltf (with FILE.bin) or FILE.glb (images embedded);\n"
          "                          implies --target gltf\n"
          "      --frames N          also write N time-lapse frames NAME_frame_0001_MAP.png ... of the\n"
          "                          crack growth (maps: those of --maps that are texture maps, else\n"
          "                          basecolor and crackmask; springs and wedge models only)\n"
          "  -j, --threads N         run parallel work on at most N threads, 1 to 256, or 0 for one\n"
          "                          per processor (default); the results do not depend on N\n"
          "      --job FILE:N        run job N (from 1) of the jobs file FILE, one job a line:\n"
          "                          PRESET SEED NAME [SECTION.KEY=VALUE]... (see fissure(1))\n"
          "      --list-jobs FILE    list the jobs of FILE, one a line, and exit\n"
          "      --progress auto|json|none\n"
          "                          progress on stderr: a line redrawn on a terminal (auto, the\n"
          "                          default), one JSON object a line (json), or none\n"
          "  -q, --quiet             print nothing on stderr but errors\n"
          "  -v, --verbose           print details of each phase on stderr\n"
          "      --list-presets      list the presets on the preset path, one a line, and exit\n"
          "      --dump-preset       print the fully resolved preset as INI and exit\n"
          "  -h, --help              print this help and exit\n"
          "  -V, --version           print the version and exit\n"
          "\n"
          "The paths of the written files go to stdout, one a line; progress goes to stderr.\n"
          "Exit status: 0 success, 64 usage error, 65 bad preset or input data, 66 missing input,\n"
          "70 internal error, 73 cannot create output, 74 I/O error.\n"
          "See fissure(1) and fissure-preset(5).\n",
          out);
}

static int usage_error(const char *fmt, const char *arg)
{
    fputs("fissure: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\nTry 'fissure --help' for more information.\n", stderr);
    return FS_ERR_USAGE;
}

/* Parses "WxH" with both sides in [16, 16384]. */
static bool parse_size(const char *s, int *w, int *h)
{
    char *end;
    errno = 0;
    long a = strtol(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X'))
        return false;
    const char *rest = end + 1;
    long b = strtol(rest, &end, 10);
    if (end == rest || *end || errno || a < 16 || b < 16 || a > 16384 || b > 16384)
        return false;
    *w = (int)a;
    *h = (int)b;
    return true;
}

static bool parse_maps(const char *list, bool *maps)
{
    memset(maps, 0, MAP_COUNT * sizeof *maps);
    char *copy = fs_strdup(list), *save = NULL;
    bool ok = true, any = false;
    for (char *tok = strtok_r(copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        bool found = false;
        if (!strcmp(tok, "all")) {
            for (int i = 0; i < MAP_COUNT; i++)
                maps[i] = true;
            found = true;
        }
        for (int i = 0; i < MAP_COUNT && !found; i++)
            if (!strcmp(tok, map_names[i]))
                maps[i] = found = true;
        ok = ok && found;
        any = any || found;
    }
    free(copy);
    return ok && any;
}

static int parse_options(int argc, char **argv, options *o)
{
    int c;
    while ((c = getopt_long(argc, argv, "o:n:s:j:qvhV", long_options, NULL)) != -1) {
        switch (c) {
        case 'o': o->output_dir = optarg; break;
        case 'n':
            if (!*optarg || strchr(optarg, '/'))
                return usage_error("--name: expected a file name prefix without '/', got '%s'", optarg);
            o->name = optarg;
            break;
        case 's': {
            char *end;
            errno = 0;
            unsigned long long v = strtoull(optarg, &end, 10);
            if (end == optarg || *end || errno || optarg[0] == '-')
                return usage_error("--seed: expected a non-negative integer, got '%s'", optarg);
            o->have_seed = true;
            o->seed = v;
            break;
        }
        case OPT_SIZE:
            if (!parse_size(optarg, &o->width, &o->height))
                return usage_error("--size: expected WxH with each side from 16 to 16384, got '%s'", optarg);
            o->have_size = true;
            break;
        case OPT_SET:
            o->sets = fs_realloc(o->sets, (size_t)(o->n_sets + 1) * sizeof *o->sets);
            o->sets[o->n_sets++] = optarg;
            break;
        case OPT_MAPS:
            o->have_maps = true;
            if (!parse_maps(optarg, o->maps))
                return usage_error("--maps: expected a comma-separated list of height, normal, basecolor, "
                                   "crackmask, crackdist, cellid, preview, occlusion, cracks or all, got '%s'",
                                   optarg);
            break;
        case OPT_FORMAT:
            if (strcmp(optarg, "png") && strcmp(optarg, "exr"))
                return usage_error("--format: expected png or exr, got '%s'", optarg);
            o->exr = !strcmp(optarg, "exr");
            break;
        case OPT_NORMAL:
            if (strcmp(optarg, "opengl") && strcmp(optarg, "directx"))
                return usage_error("--normal: expected opengl or directx, got '%s'", optarg);
            o->have_normal = true;
            o->normal = strcmp(optarg, "directx") ? FS_NORMAL_OPENGL : FS_NORMAL_DIRECTX;
            break;
        case OPT_TARGET:
            if (fs_target_parse(optarg, &o->target) < 0)
                return usage_error("--target: expected generic, gltf, unreal, unity-hdrp or blender, got '%s'",
                                   optarg);
            o->have_target = true;
            break;
        case OPT_JOB: o->job = optarg; break;
        case OPT_LIST_JOBS: o->list_jobs = optarg; break;
        case OPT_PROGRESS:
            if (strcmp(optarg, "auto") && strcmp(optarg, "json") && strcmp(optarg, "none"))
                return usage_error("--progress: expected auto, json or none, got '%s'", optarg);
            fs_progress_set_mode(!strcmp(optarg, "json")   ? FS_PROGRESS_JSON
                                 : !strcmp(optarg, "none") ? FS_PROGRESS_NONE
                                                           : FS_PROGRESS_AUTO);
            break;
        case OPT_ASSET: {
            size_t n = strlen(optarg);
            size_t stem = n > 5 && !strcasecmp(optarg + n - 5, ".gltf") ? n - 5
                          : n > 4 && !strcasecmp(optarg + n - 4, ".glb") ? n - 4
                                                                         : 0;
            if (stem == 0 || optarg[stem - 1] == '/')
                return usage_error("--asset: expected a file name ending in .gltf or .glb, got '%s'", optarg);
            o->asset_path = optarg;
            break;
        }
        case OPT_FRAMES: {
            char *end;
            errno = 0;
            long v = strtol(optarg, &end, 10);
            if (end == optarg || *end || errno || v < 1 || v > MAX_FRAMES)
                return usage_error("--frames: expected a number of frames from 1 to 10000, got '%s'",
                                   optarg);
            o->frames = (int32_t)v;
            break;
        }
        case 'j': {
            char *end;
            errno = 0;
            long v = strtol(optarg, &end, 10);
            if (end == optarg || *end || errno || v < 0 || v > FS_THREADS_MAX)
                return usage_error("--threads: expected a number of threads from 1 to 256, or 0 for one per "
                                   "processor, got '%s'",
                                   optarg);
            fs_threads_set((int)v);
            break;
        }
        case 'q': fs_log_set_level(FS_LOG_QUIET); break;
        case 'v': fs_log_set_level(FS_LOG_VERBOSE); break;
        case OPT_LIST: o->list_presets = true; break;
        case OPT_DUMP: o->dump_preset = true; break;
        case OPT_MESH:
            if (!*optarg || optarg[strlen(optarg) - 1] == '/')
                return usage_error("--mesh: expected a file name, got '%s'", optarg);
            o->mesh_path = optarg;
            break;
        case 'h': print_help(stdout); return -1;
        case 'V': printf("fissure %s\n", PACKAGE_VERSION); return -1;
        default: fputs("Try 'fissure --help' for more information.\n", stderr); return FS_ERR_USAGE;
        }
    }
    if (o->asset_path && o->have_target && o->target != FS_TARGET_GLTF)
        return usage_error("--asset binds the maps as --target gltf writes them; it cannot be used with --target %s",
                           fs_target_name(o->target));
    if (o->asset_path)
        o->target = FS_TARGET_GLTF;
    if (o->have_normal && fs_target_fixes_normal(o->target) && o->normal != fs_target_normal(o->target)) {
        char what[160];
        snprintf(what, sizeof what, "--normal %s conflicts with --target %s, whose normal maps are %s",
                 o->normal == FS_NORMAL_DIRECTX ? "directx" : "opengl", fs_target_name(o->target),
                 fs_target_normal(o->target) == FS_NORMAL_DIRECTX ? "directx" : "opengl");
        return usage_error("%s", what);
    }
    return 0;
}

static int fail(void)
{
    fs_progress_end(0, fs_error_message());
    fprintf(stderr, "fissure: %s\n", fs_error_message());
    int status = fs_error_domain();
    return status == FS_OK ? FS_ERR_INTERNAL : status;
}

/* Reads a whole (small) text file for hashing; NULL if unreadable. */
static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 4096, n = 0;
    char *buf = fs_malloc(cap);
    size_t got;
    while ((got = fread(buf + n, 1, cap - n - 1, f)) > 0) {
        n += got;
        if (cap - n < 2)
            buf = fs_realloc(buf, cap *= 2);
    }
    fclose(f);
    buf[n] = '\0';
    return buf;
}

/* Loads the preset and applies every override, in the order: file, --set, then dedicated options. */
static int load_config(const char *arg, const options *o, fs_config *cfg, char **preset_path)
{
    *cfg = fs_config_default();
    *preset_path = fs_preset_find(arg);
    if (!*preset_path || fs_preset_load(*preset_path, cfg) < 0)
        return -1;
    for (int i = 0; i < o->n_sets; i++)
        if (fs_preset_set(cfg, o->sets[i]) < 0)
            return -1;
    if (o->have_seed)
        cfg->preset.seed = o->seed;
    if (o->have_size) {
        cfg->render.width = o->width;
        cfg->render.height = o->height;
    }
    if (o->have_normal)
        cfg->render.normal = o->normal;
    if (fs_target_fixes_normal(o->target))
        cfg->render.normal = fs_target_normal(o->target);
    return fs_preset_validate(cfg, *preset_path);
}

/* Map kinds a time-lapse frame can have: the texture-space rasters. */
static bool frame_kind(int kind)
{
    return kind == MAP_HEIGHT || kind == MAP_NORMAL || kind == MAP_BASECOLOR || kind == MAP_CRACKMASK ||
           kind == MAP_CRACKDIST || kind == MAP_CELLID;
}

/* The time-lapse frames of one run: each frame is rendered and staged as it comes, in an output set
 * of its own that is committed together with the final maps. */
typedef struct {
    const options *o;
    const fs_config *cfg;
    const char *name;
    fs_output *out;                    /* the staged frame files; NULL until the first frame */
    const char *kinds[MAP_COUNT];      /* the maps of every frame */
    int n_kinds;
    double *time, *height_min, *height_max; /* per frame */
    int64_t *fractures;
    char (*file)[512];                 /* every frame file, frame by frame */
    int n_files;
    fs_sidecar_map map[MAP_COUNT];     /* per kind, from the first frame: what the sidecar says */
    fs_image header[MAP_COUNT];        /* their sizes and types (no pixels) */
    char pattern[MAP_COUNT][600];      /* their file name patterns */
} frame_writer;

static void frame_writer_init(frame_writer *fw, const options *o, const fs_config *cfg, const char *name)
{
    memset(fw, 0, sizeof *fw);
    fw->o = o;
    fw->cfg = cfg;
    fw->name = name;
    for (int i = 0; i < MAP_COUNT; i++)
        if (frame_kind(i) && o->have_maps && o->maps[i])
            fw->kinds[fw->n_kinds++] = map_names[i];
    if (fw->n_kinds == 0) {
        fw->kinds[fw->n_kinds++] = map_names[MAP_BASECOLOR];
        fw->kinds[fw->n_kinds++] = map_names[MAP_CRACKMASK];
    }
}

static void frame_writer_free(frame_writer *fw)
{
    if (fw->out)
        fs_output_abort(fw->out);
    free(fw->time);
    free(fw->height_min);
    free(fw->height_max);
    free(fw->fractures);
    free(fw->file);
    memset(fw, 0, sizeof *fw);
}

/* fs_frame_fn: renders frame k's maps and stages them as NAME_frame_KKKK_KIND.png. */
static int write_frame(void *ctx, int32_t k, int32_t count, double t, const fs_surface *surface,
                       const fs_stats *stats)
{
    frame_writer *fw = ctx;
    const fs_config *cfg = fw->cfg;
    if (!fw->out) {
        if (!(fw->out = fs_output_begin(fw->o->output_dir)))
            return -1;
        fw->time = fs_calloc((size_t)count, sizeof *fw->time);
        fw->height_min = fs_calloc((size_t)count, sizeof *fw->height_min);
        fw->height_max = fs_calloc((size_t)count, sizeof *fw->height_max);
        fw->fractures = fs_calloc((size_t)count, sizeof *fw->fractures);
        fw->file = fs_calloc((size_t)count * (size_t)fw->n_kinds, sizeof *fw->file);
    }
    fs_progress("frames", -1, "frame %d of %d at t = %.4g, %lld fractures", (int)k, (int)count, t,
                (long long)stats->fractures);
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    bool wu = fs_domain_wraps_u(&d), wv = fs_domain_wraps_v(&d);
    fs_raster raster = {0};
    fs_maps maps = {0};
    int rc = fs_render_raster(surface, cfg->render.width, cfg->render.height, cfg->render.supersample, wu, wv,
                              &raster);
    if (rc == 0)
        rc = fs_maps_build(&raster, &cfg->render, wu, wv, stats->extent_u / cfg->render.width,
                           stats->extent_v / cfg->render.height, &maps);
    char stem[560];
    snprintf(stem, sizeof stem, "%s_frame_%04d", fw->name, (int)k);
    fs_target_inputs in = {.maps = &maps, .height = &maps.height, .height_ext = "png", .normal = cfg->render.normal};
    fs_target_output *w = fs_calloc(1, sizeof *w);
    if (rc == 0)
        rc = fs_target_write(fw->out, FS_TARGET_GENERIC, stem, fw->kinds, fw->n_kinds, &in, w);
    for (int i = 0; rc == 0 && i < w->n; i++) {
        snprintf(fw->file[fw->n_files++], sizeof fw->file[0], "%s", w->file[i]);
        if (k > 1)
            continue;
        fw->map[i] = w->map[i];
        fw->header[i] = (fs_image){w->map[i].image->width, w->map[i].image->height, w->map[i].image->channels,
                                   w->map[i].image->type, NULL};
        fw->map[i].image = &fw->header[i];
        snprintf(fw->pattern[i], sizeof fw->pattern[i], "%s_frame_NNNN_%s.png", fw->name, w->map[i].kind);
        fw->map[i].file = fw->pattern[i];
    }
    fw->time[k - 1] = t;
    fw->fractures[k - 1] = stats->fractures;
    fw->height_min[k - 1] = maps.height_min_cm;
    fw->height_max[k - 1] = maps.height_max_cm;
    fs_target_output_free(w);
    free(w);
    fs_maps_free(&maps);
    fs_raster_free(&raster);
    return rc;
}

/* Writes the selected maps, the sidecar and the --mesh file as one atomic output set; prints the
 * final paths. */
static int write_outputs(const options *o, const fs_config *cfg, const char *name, const char *preset_text,
                         const fs_result *res, const fs_raster *raster, const fs_maps *maps, const fs_image *preview,
                         frame_writer *fw, double t_start)
{
    fs_output *out = fs_output_begin(o->output_dir);
    if (!out)
        return -1;
    fs_image exr_height = {0}, occlusion = {0};
    fs_crackgraph cracks = {0};
    fs_target_output *written = fs_calloc(1, sizeof *written);
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    bool wu = fs_domain_wraps_u(&d), wv = fs_domain_wraps_v(&d);
    int rc = 0;
    if (o->maps[MAP_HEIGHT] && o->exr) {
        /* Float height in cm at full precision, straight from the raster. */
        fs_image_alloc(&exr_height, raster->width, raster->height, 1, FS_PIX_F32);
        memcpy(exr_height.data, raster->height_cm, fs_image_bytes(&exr_height));
    }
    if (o->maps[MAP_OCCLUSION]) {
        fs_occlusion_params op = fs_occlusion_params_default();
        rc = fs_occlusion_build(raster, &op, wu, wv, &occlusion);
    }
    if (rc == 0 && o->maps[MAP_CRACKS]) {
        double t_graph = fs_seconds();
        fs_crackgraph_params cp = fs_crackgraph_params_default();
        rc = fs_crackgraph_build(raster, wu, wv, &cp, &cracks);
        fs_debug("crack graph: %d cracks, %d nodes, %d fragments in %.2f s", (int)cracks.n_edges,
                 (int)cracks.n_nodes, (int)cracks.n_fragments, fs_seconds() - t_graph);
    }
    const char *kinds[MAP_COUNT];
    int n_kinds = 0;
    for (int i = 0; i < MAP_COUNT; i++)
        if (o->maps[i])
            kinds[n_kinds++] = map_names[i];
    fs_target_inputs in = {.maps = maps,
                           .height = o->exr ? &exr_height : &maps->height,
                           .height_ext = o->exr ? "exr" : "png",
                           .preview = preview,
                           .occlusion = &occlusion,
                           .roughness = cfg->render.roughness,
                           .normal = cfg->render.normal,
                           .cracks = &cracks};
    if (rc == 0)
        rc = fs_target_write(out, o->target, name, kinds, n_kinds, &in, written);
    fs_image_free(&occlusion);
    fs_crackgraph_free(&cracks);
    fs_output *mesh_out = NULL, *asset_out = NULL;
    fs_config lift_cfg = *cfg; /* the lift needs the domain as read (a mesh domain's texture size) */
    lift_cfg.domain = res->mesh.domain;
    fs_asset_inputs asset = {o->mesh_path, o->asset_path, &res->surface, &lift_cfg, name, o->output_dir, out,
                             written->map, written->n, fs_target_name(o->target), maps->height_min_cm,
                             maps->height_max_cm};
    if (rc == 0)
        rc = fs_asset_stage(&asset, &mesh_out, &asset_out);
    const int n = written->n;
    char asset_files[4][1024], asset_paths[4][1024];
    int n_asset = rc == 0 ? fs_asset_files(&asset, written->map + n, asset_files, asset_paths) : 0;
    written->n += n_asset;
    char json_name[600];
    snprintf(json_name, sizeof json_name, "%s.json", name);
    char frame_pattern[600];
    snprintf(frame_pattern, sizeof frame_pattern, "%s_frame_NNNN_KIND.png", name);
    fs_sidecar_frames frames = {o->frames, frame_pattern, fw->time, fw->fractures, fw->height_min, fw->height_max,
                                fw->map, fw->n_kinds};
    if (rc == 0)
        rc = fs_sidecar_write(fs_output_stage(out, json_name), cfg, preset_text, &res->stats, maps,
                              fs_target_name(o->target), written->map, written->n, o->frames ? &frames : NULL,
                              fs_seconds() - t_start);
    fs_target_output_free(written);
    if (rc < 0) {
        free(written);
        fs_image_free(&exr_height);
        fs_output_abort(out);
        fs_output_abort(mesh_out);
        fs_output_abort(asset_out);
        return -1;
    }
    fs_image_free(&exr_height);
    if (fs_output_commit(out) < 0) {
        free(written);
        fs_output_abort(mesh_out);
        fs_output_abort(asset_out);
        return -1;
    }
    if (mesh_out && fs_output_commit(mesh_out) < 0) {
        free(written);
        fs_output_abort(asset_out);
        return -1;
    }
    if (asset_out && fs_output_commit(asset_out) < 0) {
        free(written);
        return -1;
    }
    fs_output *frames_out = fw->out;
    fw->out = NULL;
    if (frames_out && fs_output_commit(frames_out) < 0) {
        free(written);
        return -1;
    }
    for (int i = 0; i < fw->n_files; i++)
        printf("%s/%s\n", o->output_dir, fw->file[i]);
    for (int i = 0; i < n; i++)
        printf("%s/%s\n", o->output_dir, written->file[i]);
    free(written);
    printf("%s/%s\n", o->output_dir, json_name);
    for (int i = 0; i < n_asset; i++)
        printf("%s\n", asset_paths[i]);
    return 0;
}

static int run(const char *preset_arg, const options *o)
{
    double t_start = fs_seconds();
    fs_config cfg;
    char *preset_path = NULL;
    if (load_config(preset_arg, o, &cfg, &preset_path) < 0) {
        free(preset_path);
        return fail();
    }
    if (o->dump_preset) {
        fs_preset_dump(&cfg, stdout);
        free(preset_path);
        return 0;
    }
    if (o->frames > 0 && cfg.preset.model == FS_MODEL_VORONOI) {
        free(preset_path);
        return usage_error("--frames: %s", "the voronoi model has no time to show frames of; expected a springs or "
                                           "wedge preset");
    }
    char *preset_text = read_text(preset_path);
    const char *name = o->name ? o->name : cfg.preset.name;
    fs_info("%s: %s model on a %s, %d elements, seed %" PRIu64 ", %dx%d maps", preset_path,
            fs_model_name(cfg.preset.model), fs_domain_type_name(cfg.domain.type), (int)cfg.mesh.elements,
            cfg.preset.seed, cfg.render.width, cfg.render.height);
    free(preset_path);

    /* --mesh and --asset paths may hold {name}, for batches */
    options named = *o;
    char *mesh_path = o->mesh_path ? fs_job_expand_name(o->mesh_path, name) : NULL;
    char *asset_path = o->asset_path ? fs_job_expand_name(o->asset_path, name) : NULL;
    named.mesh_path = mesh_path;
    named.asset_path = asset_path;
    o = &named;

    fs_result res;
    fs_raster raster = {0};
    fs_maps maps = {0};
    fs_image preview = {0};
    frame_writer fw;
    frame_writer_init(&fw, o, &cfg, name);
    fs_sim_frames frames = {o->frames, write_frame, &fw};
    int rc = fs_sim_run_frames(&cfg, o->frames > 0 ? &frames : NULL, &res);
    if (rc == 0) {
        fs_domain d = res.mesh.domain; /* a mesh domain's texture size is known once it is read */
        bool wu = fs_domain_wraps_u(&d), wv = fs_domain_wraps_v(&d);
        fs_progress("render", -1, "%dx%d, %d triangles", cfg.render.width, cfg.render.height,
                    (int)res.surface.n_tris);
        double t_render = fs_seconds();
        rc = fs_render_raster(&res.surface, cfg.render.width, cfg.render.height, cfg.render.supersample, wu, wv,
                              &raster);
        if (rc == 0)
            rc = fs_maps_build(&raster, &cfg.render, wu, wv, fs_domain_extent_x(&d) / cfg.render.width,
                               fs_domain_extent_y(&d) / cfg.render.height, &maps);
        if (rc == 0 && o->maps[MAP_PREVIEW])
            rc = fs_render_preview(&res.surface, &d, &cfg.render, &maps, &preview);
        fs_progress_done();
        fs_debug("rendered in %.2f s", fs_seconds() - t_render);
        if (rc == 0)
            rc = write_outputs(o, &cfg, name, preset_text, &res, &raster, &maps, &preview, &fw, t_start);
        fs_result_free(&res);
    }
    fs_maps_free(&maps);
    fs_image_free(&preview);
    fs_raster_free(&raster);
    frame_writer_free(&fw);
    free(preset_text);
    free(mesh_path);
    free(asset_path);
    if (rc < 0)
        return fail();
    char done[64];
    snprintf(done, sizeof done, "done in %.1f s", fs_seconds() - t_start);
    fs_progress_end(1, done);
    fs_info("%s", done);
    return 0;
}

/* --job FILE:N: the run `fissure [OPTION]... -s SEED -n NAME --set OVERRIDE... PRESET` of job N,
 * the job's overrides after the command line's. */
static int run_job(options *o, int n_args)
{
    if (n_args > 0)
        return usage_error("%s", "--job: the job names its preset; expected no PRESET argument");
    if (o->have_seed || o->name)
        return usage_error("--job: the job sets %s; expected no --seed or --name beside it",
                           o->have_seed ? "the seed" : "the output name");
    fs_job job;
    if (fs_job_load(o->job, &job) < 0) {
        if (fs_error_domain() == FS_ERR_USAGE)
            return usage_error("%s", fs_error_message());
        return fail();
    }
    o->have_seed = true;
    o->seed = job.seed;
    o->name = job.name;
    o->sets = fs_realloc(o->sets, (size_t)(o->n_sets + job.n_sets + 1) * sizeof *o->sets);
    for (int k = 0; k < job.n_sets; k++)
        o->sets[o->n_sets++] = job.sets[k];
    fs_debug("%s: job on line %d", o->job, job.line);
    int rc = run(job.preset, o);
    fs_jobs_free(&job, 1);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "diff"))
        return fs_cli_diff(argc - 1, argv + 1);

    options o = {.output_dir = "."};
    for (int i = 0; i < MAP_COUNT; i++)
        o.maps[i] = i != MAP_PREVIEW;
    int rc = parse_options(argc, argv, &o);
    if (rc != 0) {
        free(o.sets);
        return rc < 0 ? 0 : rc;
    }
    if (o.list_presets) {
        free(o.sets);
        return fs_preset_list(stdout) < 0 ? fail() : 0;
    }
    if (o.list_jobs) {
        free(o.sets);
        return fs_jobs_list(o.list_jobs, stdout) < 0 ? fail() : 0;
    }
    if (o.job) {
        rc = run_job(&o, argc - optind);
        free(o.sets);
        return rc;
    }
    if (optind != argc - 1) {
        free(o.sets);
        return usage_error("%s", optind >= argc ? "missing PRESET argument" : "expected exactly one PRESET argument");
    }
    rc = run(argv[optind], &o);
    free(o.sets);
    return rc;
}
