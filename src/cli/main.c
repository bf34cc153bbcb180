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
#include "io/output.h"
#include "io/outputs.h"
#include "io/preset.h"
#include "sim/sim.h"

typedef struct {
    const char *output_dir;
    const char *name;
    bool have_seed;
    uint64_t seed;
    bool have_size;
    int width, height;
    char **sets;
    int n_sets;
    bool maps[FS_MAP_COUNT];
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

/* Longest -n/--name in bytes: with the longest suffix fissure adds (a frame's
 * "_frame_NNNN_crackmask.png", a glTF "_occlusionRoughnessMetallic.png", "T_" before an Unreal map)
 * and the staging name's ".", ".tmp-PID-N", every file name stays under NAME_MAX (255). */
#define MAX_NAME_BYTES 128
/* Longest file name a run stages for a NAME of n bytes, as fs_output_check wants it. */
#define STAGED_NAME_BYTES(n) ((n) + 2 + 31 + 1 + 5 + 20 + 1 + 20)

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
          "                          basecolor and crackmask; not the voronoi model)\n"
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

/* Whether s is UTF-8 (shortest forms, no surrogates, at most U+10FFFF). */
static bool utf8_valid(const char *s)
{
    const unsigned char *p = (const unsigned char *)s;
    while (*p) {
        unsigned c = *p;
        int more = c < 0x80 ? 0 : (c & 0xe0) == 0xc0 ? 1 : (c & 0xf0) == 0xe0 ? 2 : (c & 0xf8) == 0xf0 ? 3 : -1;
        if (more < 0 || (more == 1 && c < 0xc2))
            return false;
        unsigned cp = more == 0 ? c : c & (0x3fu >> more);
        for (int k = 1; k <= more; k++) {
            if ((p[k] & 0xc0) != 0x80)
                return false;
            cp = (cp << 6) | (p[k] & 0x3fu);
        }
        if ((more == 2 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) || (more == 3 && (cp < 0x10000 || cp > 0x10ffff)))
            return false;
        p += more + 1;
    }
    return true;
}

/* Whether s has a control character (a newline would break "one path a line" on stdout). */
static bool has_control(const char *s)
{
    for (const unsigned char *p = (const unsigned char *)s; *p; p++)
        if (*p < 0x20 || *p == 0x7f)
            return true;
    return false;
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
    memset(maps, 0, FS_MAP_COUNT * sizeof *maps);
    char *copy = fs_strdup(list), *save = NULL;
    bool ok = true, any = false;
    for (char *tok = strtok_r(copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        bool found = false;
        if (!strcmp(tok, "all")) {
            for (int i = 0; i < FS_MAP_COUNT; i++)
                maps[i] = true;
            found = true;
        }
        for (int i = 0; i < FS_MAP_COUNT && !found; i++)
            if (!strcmp(tok, fs_map_name(i)))
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
        case 'o':
            if (has_control(optarg))
                return usage_error("--output: expected a directory name without control characters, got '%s'",
                                   optarg);
            o->output_dir = optarg;
            break;
        case 'n':
            if (!*optarg || strchr(optarg, '/') || has_control(optarg) || !utf8_valid(optarg) ||
                strlen(optarg) > MAX_NAME_BYTES)
                return usage_error("--name: expected a file name prefix of 1 to 128 bytes of UTF-8 without '/' or "
                                   "control characters, got '%s'",
                                   optarg);
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
            if (!*optarg || optarg[strlen(optarg) - 1] == '/' || has_control(optarg))
                return usage_error("--mesh: expected a file name without control characters, got '%s'", optarg);
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

/* Checks, before the run, that the outputs can be created: the output directory (or the ancestor
 * it would be created in) and the directories of the --mesh and --asset files are writable
 * directories. */
static int check_outputs(const options *o, const char *name)
{
    if (fs_output_check(o->output_dir, STAGED_NAME_BYTES(strlen(name))) < 0)
        return -1;
    const char *beside[2] = {o->mesh_path, o->asset_path};
    for (int i = 0; i < 2; i++) {
        if (!beside[i])
            continue;
        const char *file;
        char *dir = fs_output_dir_of(beside[i], &file);
        int rc = fs_output_check(dir, STAGED_NAME_BYTES(strlen(file)));
        free(dir);
        if (rc < 0)
            return -1;
    }
    return 0;
}

/* The time-lapse frames of one run: each frame is rendered and staged as it comes, in an output set
 * of its own that is committed together with the final maps. */
typedef struct {
    const options *o;
    const fs_config *cfg;
    const char *name;
    fs_output *out;                    /* the staged frame files; NULL until the first frame */
    const char *kinds[FS_MAP_COUNT];      /* the maps of every frame */
    int n_kinds;
    double *time, *height_min, *height_max; /* per frame */
    int64_t *fractures;
    char (*file)[512];                 /* every frame file, frame by frame */
    int n_files;
    fs_sidecar_map map[FS_MAP_COUNT];     /* per kind, from the first frame: what the sidecar says */
    fs_image header[FS_MAP_COUNT];        /* their sizes and types (no pixels) */
    char pattern[FS_MAP_COUNT][600];      /* their file name patterns */
} frame_writer;

static void frame_writer_init(frame_writer *fw, const options *o, const fs_config *cfg, const char *name)
{
    memset(fw, 0, sizeof *fw);
    fw->o = o;
    fw->cfg = cfg;
    fw->name = name;
    for (int i = 0; i < FS_MAP_COUNT; i++)
        if (fs_map_is_raster(i) && o->have_maps && o->maps[i])
            fw->kinds[fw->n_kinds++] = fs_map_name(i);
    if (fw->n_kinds == 0) {
        fw->kinds[fw->n_kinds++] = fs_map_name(FS_MAP_BASECOLOR);
        fw->kinds[fw->n_kinds++] = fs_map_name(FS_MAP_CRACKMASK);
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
    bool kinds[FS_MAP_COUNT] = {false};
    fs_outputs built;
    fs_config frame_cfg = *cfg; /* a mesh domain's cm per texture unit are known once it is read */
    if (frame_cfg.domain.type == FS_DOMAIN_MESH) {
        frame_cfg.domain.width = stats->extent_u;
        frame_cfg.domain.height = stats->extent_v;
    }
    int rc = fs_outputs_build(surface, &frame_cfg, kinds, false, &built);
    char stem[560];
    snprintf(stem, sizeof stem, "%s_frame_%04d", fw->name, (int)k);
    fs_target_inputs in = {.maps = &built.maps, .height = &built.maps.height, .height_ext = "png",
                           .normal = cfg->render.normal};
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
    fw->height_min[k - 1] = built.maps.height_min_cm;
    fw->height_max[k - 1] = built.maps.height_max_cm;
    fs_target_output_free(w);
    free(w);
    fs_outputs_free(&built);
    return rc;
}

/* Writes the run's outputs as one set (io/outputs.h) with the staged frames, and prints the final
 * paths, the frames' first. */
static int write_outputs(const options *o, const fs_config *cfg, const char *name, const char *preset_text,
                         const fs_result *res, const fs_outputs *built, frame_writer *fw, double t_start)
{
    char frame_pattern[600];
    snprintf(frame_pattern, sizeof frame_pattern, "%s_frame_NNNN_KIND.png", name);
    fs_sidecar_frames frames = {o->frames, frame_pattern, fw->time, fw->fractures, fw->height_min, fw->height_max,
                                fw->map, fw->n_kinds};
    fs_outputs_request r = {.output_dir = o->output_dir,
                            .name = name,
                            .exr = o->exr,
                            .target = o->target,
                            .mesh_path = o->mesh_path,
                            .asset_path = o->asset_path,
                            .solid = &res->solid,
                            .preset_text = preset_text,
                            .frames = fw->out,
                            .frame_info = o->frames ? &frames : NULL,
                            .t_start = t_start};
    memcpy(r.kinds, o->maps, sizeof r.kinds);
    fw->out = NULL;
    fs_outputs_paths paths;
    if (fs_outputs_write(built, &res->surface, cfg, &res->stats, &r, &paths) < 0)
        return -1;
    for (int i = 0; i < fw->n_files; i++)
        printf("%s/%s\n", o->output_dir, fw->file[i]);
    for (int i = 0; i < paths.n; i++)
        printf("%s\n", paths.path[i]);
    fs_outputs_paths_free(&paths);
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
    const char *name = o->name ? o->name : cfg.preset.name;
    /* --mesh and --asset paths may hold {name}, for batches */
    options named = *o;
    char *mesh_path = o->mesh_path ? fs_job_expand_name(o->mesh_path, name) : NULL;
    char *asset_path = o->asset_path ? fs_job_expand_name(o->asset_path, name) : NULL;
    named.mesh_path = mesh_path;
    named.asset_path = asset_path;
    o = &named;
    if (check_outputs(o, name) < 0) {
        free(preset_path);
        free(mesh_path);
        free(asset_path);
        return fail();
    }
    char *preset_text = fs_preset_read_text(preset_path);
    fs_error_clear();
    fs_info("%s: %s model on a %s, %d elements, seed %" PRIu64 ", %dx%d maps", preset_path,
            fs_model_name(cfg.preset.model), fs_domain_type_name(cfg.domain.type), (int)cfg.mesh.elements,
            cfg.preset.seed, cfg.render.width, cfg.render.height);
    free(preset_path);

    fs_result res;
    fs_outputs built = {0};
    frame_writer fw;
    frame_writer_init(&fw, o, &cfg, name);
    fs_sim_frames frames = {o->frames, write_frame, &fw};
    int rc = fs_sim_run_frames(&cfg, o->frames > 0 ? &frames : NULL, &res);
    if (rc == 0) {
        if (cfg.domain.type == FS_DOMAIN_MESH)
            cfg.domain = res.mesh.domain; /* a mesh domain's texture size is known once it is read */
        fs_progress("render", -1, "%dx%d, %d triangles", cfg.render.width, cfg.render.height,
                    (int)res.surface.n_tris);
        rc = fs_outputs_build(&res.surface, &cfg, o->maps, o->exr, &built);
        fs_progress_done();
        fs_debug("rendered in %.2f s (raster %.2f s, maps %.2f s, preview %.2f s, occlusion %.2f s, crack graph "
                 "%.2f s)", built.render_seconds + built.maps_seconds + built.preview_seconds +
                 built.occlusion_seconds + built.cracks_seconds, built.render_seconds, built.maps_seconds,
                 built.preview_seconds, built.occlusion_seconds, built.cracks_seconds);
        if (rc == 0)
            rc = write_outputs(o, &cfg, name, preset_text, &res, &built, &fw, t_start);
        fs_result_free(&res);
    }
    fs_outputs_free(&built);
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

/* Runs before the shared libraries' constructors, some of which start threads (OpenBLAS its pool):
 * blocking the termination signals here gives every thread of the process the blocked mask, so
 * that only fissure's cleanup thread takes them (io/output.h). */
static void block_signals_early(int argc, char **argv, char **envp)
{
    (void)argc;
    (void)argv;
    (void)envp;
    fs_output_block_signals();
}
__attribute__((section(".preinit_array"), used)) static void (*const preinit_block_signals)(int, char **,
                                                                                          char **) = block_signals_early;

int main(int argc, char **argv)
{
    fs_alloc_setup();
    /* every mode: the termination signals are blocked from the preinit array on, and taken here */
    if (fs_output_cleanup_on_signals() < 0)
        return fail();
    if (argc > 1 && !strcmp(argv[1], "diff"))
        return fs_cli_diff(argc - 1, argv + 1);

    options o = {.output_dir = "."};
    for (int i = 0; i < FS_MAP_COUNT; i++)
        o.maps[i] = i != FS_MAP_PREVIEW;
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
