/* Shared set-up of the wedge model's unit tests: a test mesh and the stretched strip. */
#ifndef FS_TESTS_WEDGE_FIXTURE_H
#define FS_TESTS_WEDGE_FIXTURE_H

#include "geom/delaunay.h"
#include "geom/sample.h"
#include "model/wedge/internal.h"

/* A mesh of about `points` nodes sampled by repulsion on cfg's domain with cfg's seed. Returns 0 or
 * -1 with fs_error. */
static inline int wedge_test_mesh(const fs_config *cfg, int32_t points, fs_mesh *m)
{
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = points;
    sp.seed = cfg->preset.seed;
    fs_points pts = {0};
    if (fs_sample_repulsion(&d, &sp, &pts) < 0)
        return -1;
    int rc = fs_delaunay(&d, &pts, m);
    fs_points_free(&pts);
    return rc;
}

/* A periodic 4 x 4 cm layer (E = 10 MPa, nu = 0.3, threshold 100 kPa, 0.2 cm thick) stretched along
 * x by planar growth (r1 along x, nothing along y): uniaxial tension sigma_xx. */
static inline fs_config wedge_strip_config(void)
{
    fs_config c = fs_config_default();
    c.preset.model = FS_MODEL_WEDGE;
    c.preset.seed = 3;
    c.domain.type = FS_DOMAIN_PLANE;
    c.domain.width = 4.0;
    c.domain.height = 4.0;
    c.domain.periodic_x = c.domain.periodic_y = true;
    c.material.young = 10.0;
    c.material.poisson = 0.3;
    c.material.threshold = 100.0;
    c.material.jitter = 0.1;
    c.material.thickness = 0.2;
    c.material.thickness_final = -1.0;
    c.material.toughness = 0.0;
    c.growth.type = FS_GROWTH_PLANAR;
    c.growth.r1 = 0.05;
    c.growth.r2 = 0.0;
    c.growth.angle = 0.0;
    c.fracture.method = FS_FRACTURE_SPLIT;
    c.fracture.griffith = false;
    c.time.end = 1.0;
    c.time.min_step = 1e-3;
    c.mesh.min_size = 1e3;
    c.solver.relax = FS_RELAX_LOCAL;
    return c;
}

#endif
