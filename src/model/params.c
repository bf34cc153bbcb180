/* The defaults of the settings the physical models share. */
#include "model/params.h"

fs_mesh_params fs_mesh_params_default(void)
{
    return (fs_mesh_params){
        .elements = 1000,
        .min_size = 0.05,
        .lattice = FS_LATTICE_RANDOM,
        .relax_iterations = 30,
        .radius_jitter = 0.2,
        .refine_vm = 0.0,
        .refine_vm_rounds = 3,
        .smooth_radius = 0.0,
        .smooth_iterations = 3,
    };
}

fs_fracture_params fs_fracture_params_default(void)
{
    return (fs_fracture_params){
        .method = FS_FRACTURE_SPLIT,
        .griffith = true,
        .tip_submodel = false,
        .tip_submodel_radius = 4.0,
        .tip_submodel_size = 0.25,
        .direction_radius = 1.5,
    };
}

fs_time_params fs_time_params_default(void) { return (fs_time_params){.end = 1.0, .min_step = 1e-4}; }

fs_solver_params fs_solver_params_default(void)
{
    return (fs_solver_params){
        .method = FS_SOLVER_CHOLMOD,
        .tolerance = 1e-8,
        .max_iterations = 0,
        .relax = FS_RELAX_AUTO,
        .relax_radius = 4.0,
        .relax_tolerance = 3e-2,
    };
}
