/* The model interface: one switch on the kind per call. */
#include "model/model.h"

#include <string.h>

#include "base/error.h"

const char *fs_model_name(fs_model_kind kind)
{
    switch (kind) {
    case FS_MODEL_VORONOI: return "voronoi";
    case FS_MODEL_SPRINGS: return "springs";
    case FS_MODEL_WEDGE: return "wedge";
    case FS_MODEL_SHELL: return "shell";
    case FS_MODEL_TET: return "tet";
    }
    return "unknown";
}

fs_model_setup fs_model_setup_default(void)
{
    fs_model_setup s;
    memset(&s, 0, sizeof s);
    s.kind = FS_MODEL_VORONOI;
    s.seed = 1;
    s.opening_scale = 1.0;
    s.mesh = fs_mesh_params_default();
    s.material = fs_material_default();
    s.growth = fs_growth_default();
    s.shrink = fs_shrink_default();
    s.fracture = fs_fracture_params_default();
    s.time = fs_time_params_default();
    s.solver = fs_solver_params_default();
    s.voronoi = fs_voronoi_params_default();
    s.springs = fs_springs_params_default();
    s.wedge = fs_wedge_params_default();
    s.tet = fs_tet_params_default();
    s.shell = fs_shell_params_default();
    return s;
}

int fs_model_init(fs_model *m, fs_mesh *mesh, const fs_model_setup *setup)
{
    memset(m, 0, sizeof *m);
    m->kind = setup->kind;
    m->mesh = mesh;
    m->setup = setup;
    switch (setup->kind) {
    case FS_MODEL_VORONOI: return 0;
    case FS_MODEL_SPRINGS: return (m->state.springs = fs_springs_create(mesh, setup)) ? 0 : -1;
    case FS_MODEL_WEDGE: return (m->state.wedge = fs_wedge_create(mesh, setup)) ? 0 : -1;
    case FS_MODEL_TET: return (m->state.tet = fs_tet_create(mesh, setup)) ? 0 : -1;
    case FS_MODEL_SHELL: return (m->state.shell = fs_shell_create(mesh, setup)) ? 0 : -1;
    }
    fs_error(FS_ERR_DATA, "[preset] model: unknown model kind %d; expected voronoi, springs, wedge, tet or shell",
             (int)setup->kind);
    return -1;
}

int fs_model_advance(fs_model *m, double t)
{
    switch (m->kind) {
    case FS_MODEL_SPRINGS: return fs_springs_advance(m->state.springs, t);
    case FS_MODEL_WEDGE: return fs_wedge_advance(m->state.wedge, t);
    case FS_MODEL_TET: return fs_tet_advance(m->state.tet, t);
    case FS_MODEL_SHELL: return fs_shell_advance(m->state.shell, t);
    default: return 0;
    }
}

int fs_model_surface(const fs_model *m, fs_surface *out)
{
    switch (m->kind) {
    case FS_MODEL_VORONOI: return fs_voronoi_surface(m->mesh, &m->setup->voronoi, m->setup->seed, out);
    case FS_MODEL_SPRINGS: return fs_springs_surface(m->state.springs, out);
    case FS_MODEL_WEDGE: return fs_wedge_surface(m->state.wedge, out);
    case FS_MODEL_TET: return fs_tet_surface(m->state.tet, out);
    case FS_MODEL_SHELL: return fs_shell_surface(m->state.shell, out);
    default: FS_ASSERT(!"fs_model_surface of a model that was not built"); return -1;
    }
}

int fs_model_solid(const fs_model *m, fs_solid *out)
{
    switch (m->kind) {
    case FS_MODEL_TET: return fs_tet_solid(m->state.tet, out) < 0 ? -1 : 1;
    default: return 0;
    }
}

fs_model_info fs_model_stats(const fs_model *m)
{
    switch (m->kind) {
    case FS_MODEL_SPRINGS: return fs_springs_info(m->state.springs);
    case FS_MODEL_WEDGE: return fs_wedge_info(m->state.wedge);
    case FS_MODEL_TET: return fs_tet_info(m->state.tet);
    case FS_MODEL_SHELL: return fs_shell_info(m->state.shell);
    default: return (fs_model_info){0, 0.0};
    }
}

void fs_model_report(const fs_model *m)
{
    switch (m->kind) {
    case FS_MODEL_SPRINGS: fs_springs_report(m->state.springs); break;
    case FS_MODEL_WEDGE: fs_wedge_report(m->state.wedge); break;
    case FS_MODEL_TET: fs_tet_report(m->state.tet); break;
    case FS_MODEL_SHELL: fs_shell_report(m->state.shell); break;
    default: break;
    }
}

void fs_model_free(fs_model *m)
{
    switch (m->kind) {
    case FS_MODEL_SPRINGS: fs_springs_destroy(m->state.springs); break;
    case FS_MODEL_WEDGE: fs_wedge_destroy(m->state.wedge); break;
    case FS_MODEL_TET: fs_tet_destroy(m->state.tet); break;
    case FS_MODEL_SHELL: fs_shell_destroy(m->state.shell); break;
    default: break;
    }
    memset(m, 0, sizeof *m);
}
