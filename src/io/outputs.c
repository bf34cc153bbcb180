/* The pipeline from a run's surface to its files, for the command line and the benchmarks. */
#include "io/outputs.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "io/asset.h"
#include "render/occlusion.h"

static const char *const map_names[FS_MAP_COUNT] = {"height", "normal",  "basecolor", "crackmask", "crackdist",
                                                    "cellid", "preview", "occlusion", "cracks"};

const char *fs_map_name(fs_map_kind kind) { return kind < FS_MAP_COUNT ? map_names[kind] : "unknown"; }

bool fs_map_is_raster(fs_map_kind kind) { return kind <= FS_MAP_CELLID; }

int fs_outputs_build(const fs_surface *surface, const fs_config *cfg, const bool kinds[FS_MAP_COUNT], bool exr,
                     fs_outputs *out)
{
    memset(out, 0, sizeof *out);
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    bool wu = fs_domain_wraps_u(&d), wv = fs_domain_wraps_v(&d);
    const fs_render_params *p = &cfg->render;
    double t0 = fs_seconds();
    if (fs_render_raster(surface, p->width, p->height, p->supersample, wu, wv, &out->raster) < 0)
        return -1;
    double t1 = fs_seconds();
    out->render_seconds = t1 - t0;
    if (fs_maps_build(&out->raster, p, wu, wv, fs_domain_extent_x(&d) / p->width, fs_domain_extent_y(&d) / p->height,
                      &out->maps) < 0)
        return -1;
    double t2 = fs_seconds();
    out->maps_seconds = t2 - t1;
    if (kinds[FS_MAP_HEIGHT] && exr) {
        fs_image_alloc(&out->exr_height, out->raster.width, out->raster.height, 1, FS_PIX_F32);
        memcpy(out->exr_height.data, out->raster.height_cm, fs_image_bytes(&out->exr_height));
    }
    if (kinds[FS_MAP_PREVIEW] && fs_render_preview(surface, &d, p, &out->maps, &out->preview) < 0)
        return -1;
    double t3 = fs_seconds();
    out->preview_seconds = t3 - t2;
    if (kinds[FS_MAP_OCCLUSION]) {
        fs_occlusion_params op = fs_occlusion_params_default();
        if (fs_occlusion_build(&out->raster, &op, wu, wv, &out->occlusion) < 0)
            return -1;
    }
    double t4 = fs_seconds();
    out->occlusion_seconds = t4 - t3;
    if (kinds[FS_MAP_CRACKS]) {
        fs_crackgraph_params cp = fs_crackgraph_params_default();
        if (fs_crackgraph_build(&out->raster, wu, wv, &cp, &out->cracks) < 0)
            return -1;
        fs_debug("crack graph: %d cracks, %d nodes, %d fragments", (int)out->cracks.n_edges, (int)out->cracks.n_nodes,
                 (int)out->cracks.n_fragments);
    }
    out->cracks_seconds = fs_seconds() - t4;
    return 0;
}

void fs_outputs_free(fs_outputs *o)
{
    fs_raster_free(&o->raster);
    fs_maps_free(&o->maps);
    fs_image_free(&o->exr_height);
    fs_image_free(&o->preview);
    fs_image_free(&o->occlusion);
    fs_crackgraph_free(&o->cracks);
    memset(o, 0, sizeof *o);
}

void fs_outputs_paths_free(fs_outputs_paths *p)
{
    for (int i = 0; i < p->n; i++)
        free(p->path[i]);
    free(p->path);
    memset(p, 0, sizeof *p);
}

static void add_path(fs_outputs_paths *p, const char *dir, const char *file)
{
    p->path = fs_realloc(p->path, (size_t)(p->n + 1) * sizeof *p->path);
    size_t n = (dir ? strlen(dir) + 1 : 0) + strlen(file) + 1;
    p->path[p->n] = fs_malloc(n);
    snprintf(p->path[p->n], n, "%s%s%s", dir ? dir : "", dir ? "/" : "", file);
    p->n++;
}

int fs_outputs_write(const fs_outputs *b, const fs_surface *surface, const fs_config *cfg, const fs_stats *stats,
                     const fs_outputs_request *r, fs_outputs_paths *paths)
{
    memset(paths, 0, sizeof *paths);
    fs_output *out = fs_output_begin(r->output_dir);
    if (!out) {
        fs_output_abort(r->frames);
        return -1;
    }
    const char *kinds[FS_MAP_COUNT];
    int n_kinds = 0;
    for (int i = 0; i < FS_MAP_COUNT; i++)
        if (r->kinds[i])
            kinds[n_kinds++] = map_names[i];
    fs_target_inputs in = {.maps = &b->maps,
                           .height = r->exr ? &b->exr_height : &b->maps.height,
                           .height_ext = r->exr ? "exr" : "png",
                           .preview = &b->preview,
                           .occlusion = &b->occlusion,
                           .roughness = cfg->render.roughness,
                           .normal = cfg->render.normal,
                           .cracks = &b->cracks};
    fs_target_output *written = fs_calloc(1, sizeof *written);
    int rc = fs_target_write(out, r->target, r->name, kinds, n_kinds, &in, written);
    const int n_maps = written->n;

    /* the 3-D files, staged beside their own paths, then taken into the one set */
    fs_output *mesh_out = NULL, *asset_out = NULL;
    fs_asset_inputs asset = {r->mesh_path, r->asset_path, surface, cfg, r->name, r->output_dir, out,
                             written->map, written->n, fs_target_name(r->target), b->maps.height_min_cm,
                             b->maps.height_max_cm};
    if (rc == 0)
        rc = fs_asset_stage(&asset, &mesh_out, &asset_out);
    char asset_files[4][1024], asset_paths[4][1024];
    int n_asset = rc == 0 ? fs_asset_files(&asset, written->map + n_maps, asset_files, asset_paths) : 0;
    written->n += n_asset;
    fs_output_merge(out, r->frames);
    fs_output_merge(out, mesh_out);
    fs_output_merge(out, asset_out);

    /* the sidecar names every file of the set and is moved into place last */
    int n_files;
    const char **files = fs_output_names(out, &n_files);
    char json_name[600];
    snprintf(json_name, sizeof json_name, "%s.json", r->name);
    if (rc == 0)
        rc = fs_sidecar_write(fs_output_stage_seal(out, json_name), cfg, r->preset_text, stats, &b->maps,
                              fs_target_name(r->target), written->map, written->n, r->frame_info, files, n_files,
                              fs_seconds() - r->t_start);
    free(files);
    fs_target_output_free(written);
    if (rc < 0) {
        fs_output_abort(out);
    } else if ((rc = fs_output_commit(out)) == 0) {
        for (int i = 0; i < n_maps; i++)
            add_path(paths, r->output_dir, written->file[i]);
        add_path(paths, r->output_dir, json_name);
        for (int i = 0; i < n_asset; i++)
            add_path(paths, NULL, asset_paths[i]);
    }
    free(written);
    return rc;
}
