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

    c.mesh.elements = 1000;
    c.mesh.min_size = 0.05;
    c.mesh.lattice = FS_LATTICE_RANDOM;
    c.mesh.relax_iterations = 30;
    c.mesh.radius_jitter = 0.2;
    c.mesh.refine_vm = 0.0;
    c.mesh.refine_vm_rounds = 3;
    c.mesh.smooth_radius = 0.0;
    c.mesh.smooth_iterations = 3;

    c.material = fs_material_default();
    c.growth = fs_growth_default();
    c.shrink = fs_shrink_default();

    c.fracture.method = FS_FRACTURE_SPLIT;
    c.fracture.griffith = true;
    c.fracture.tip_submodel = false;
    c.fracture.tip_submodel_radius = 4.0;
    c.fracture.tip_submodel_size = 0.25;

    c.time.end = 1.0;
    c.time.min_step = 1e-4;

    c.render = fs_render_params_default();
    c.voronoi = fs_voronoi_params_default();
    c.springs = fs_springs_params_default();

    c.solver.method = FS_SOLVER_CHOLMOD;
    c.solver.tolerance = 1e-8;
    c.solver.max_iterations = 0;
    c.solver.relax = FS_RELAX_AUTO;
    c.solver.relax_radius = 4.0;
    c.solver.relax_tolerance = 3e-2;

    c.wedge.thickness_gradient = 0.0;
    return c;
}

const char *fs_model_name(fs_model_type m)
{
    switch (m) {
    case FS_MODEL_VORONOI: return "voronoi";
    case FS_MODEL_SPRINGS: return "springs";
    case FS_MODEL_WEDGE: return "wedge";
    case FS_MODEL_SHELL: return "shell";
    case FS_MODEL_TET: return "tet";
    }
    return "unknown";
}
