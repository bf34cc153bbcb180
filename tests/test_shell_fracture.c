/* Tests of the shell model's fracture: crack direction under tension. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"
#include "check.h"
#include "mesh_fixture.h"
#include "geom/uvmesh.h"
#include "model/model.h"
#include "model/shell/internal.h"

/* A layer E = 10 MPa, nu = 0.3, threshold 100 kPa, h cm thick, bonded (shell) or on its bottom (wedge). */
static fs_model_setup layer(fs_model_kind kind, double h)
{
    fs_model_setup s = fs_model_setup_default();
    s.kind = kind;
    s.seed = 4;
    s.material.young = 10.0;
    s.material.poisson = 0.3;
    s.material.threshold = 100.0;
    s.material.thickness = h;
    s.material.thickness_final = -1.0;
    s.material.jitter = 0.1;
    s.time.end = 1.0;
    s.time.min_step = 0.01;
    s.mesh.min_size = 1e3;
    s.fracture.method = FS_FRACTURE_SPLIT;
    s.fracture.griffith = false;
    return s;
}

/* The walls of the cracks: boundary half-edges whose pair of origins appears twice (the two walls). */
static int32_t crack_walls(const fs_shell *s, int32_t *walls)
{
    const fs_mesh *m = s->mesh;
    int32_t n = 0;
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int i = 0; i < 3; i++)
            if (m->adj[3 * t + i] < 0)
                walls[n++] = 3 * t + i;
    return n;
}

/* Stretched along x (planar growth, eigenstrain on the periodic tile), the layer cracks across x:
 * its crack walls run along y. */
static void test_tension_cracks_across(void)
{
    fs_mesh m = {0};
    CHECK(sampled_tile(4.0, 600, 3, &m) == 0);
    fs_model_setup s = layer(FS_MODEL_SHELL, 0.2);
    s.growth.type = FS_GROWTH_PLANAR;
    s.growth.r1 = 0.03;
    s.growth.r2 = 0.0;
    s.growth.angle = 0.0;
    fs_model model;
    CHECK_MSG(fs_model_init(&model, &m, &s) == 0, "%s", fs_error_message());
    CHECK(fs_model_advance(&model, 1.0) == 0);
    const fs_shell *sh = model.state.shell;
    CHECK_MSG(sh->fractures > 0, "no fracture under 3 %% stretch");
    int32_t *walls = malloc(3 * (size_t)m.n_tris * sizeof *walls);
    int32_t n = crack_walls(sh, walls);
    double along_x = 0.0, along_y = 0.0;
    for (int32_t q = 0; q < n; q++) {
        int32_t t = walls[q] / 3, i = walls[q] % 3;
        double a[3], b[3];
        fs_shell_corner(sh, sh->rest, t, i, a);
        fs_shell_corner(sh, sh->rest, t, (i + 1) % 3, b);
        along_x += fabs(b[0] - a[0]);
        along_y += fabs(b[1] - a[1]);
    }
    printf("  %lld fractures, %d crack walls: %.2f cm along x, %.2f cm along y\n", (long long)sh->fractures, (int)n,
           along_x, along_y);
    CHECK_MSG(along_y > 2.5 * along_x, "cracks along x %g, along y %g", along_x, along_y);
    free(walls);
    fs_model_free(&model);
    fs_mesh_free(&m);
}

int main(void)
{
    RUN(test_tension_cracks_across);
    return check_finish();
}
