/* The default configuration of a run, assembled from each section's defaults function. */
#include "sim/settings.h"

#include <string.h>

fs_config fs_config_default(void)
{
    fs_config c;
    memset(&c, 0, sizeof c);
    strcpy(c.preset.name, "unnamed");
    c.preset.description[0] = '\0';
    c.preset.model = FS_MODEL_VORONOI;
    c.preset.seed = 1;
    c.domain = fs_domain_default();
    c.mesh = fs_mesh_params_default();
    c.material = fs_material_default();
    c.growth = fs_growth_default();
    c.shrink = fs_shrink_default();
    c.fracture = fs_fracture_params_default();
    c.time = fs_time_params_default();
    c.render = fs_render_params_default();
    c.voronoi = fs_voronoi_params_default();
    c.springs = fs_springs_params_default();
    c.solver = fs_solver_params_default();
    c.wedge = fs_wedge_params_default();
    c.tet = fs_tet_params_default();
    c.shell = fs_shell_params_default();
    return c;
}

fs_model_setup fs_config_model_setup(const fs_config *cfg)
{
    fs_model_setup s = fs_model_setup_default();
    s.kind = cfg->preset.model;
    s.seed = cfg->preset.seed;
    s.mesh = cfg->mesh;
    s.material = cfg->material;
    s.growth = cfg->growth;
    s.shrink = cfg->shrink;
    s.fracture = cfg->fracture;
    s.time = cfg->time;
    s.solver = cfg->solver;
    s.voronoi = cfg->voronoi;
    s.springs = cfg->springs;
    s.wedge = cfg->wedge;
    s.tet = cfg->tet;
    s.shell = cfg->shell;
    s.opening_scale = cfg->render.opening_scale;
    s.wall_slope = cfg->render.wall_slope;
    return s;
}
