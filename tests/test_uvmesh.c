/* Tests of the UV-mapped mesh reader: welding across seams, the texture scale, and every refusal. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "check.h"
#include "geom/uvmesh.h"

static int parse(const char *text, fs_mesh *m, double **uv)
{
    return fs_uvmesh_parse(text, strlen(text), "t.obj", m, uv);
}

/* A unit square of two triangles whose right triangle is mapped into a chart of its own: the two
 * share an edge in space (welded, adjacent) but not in texture space (a seam). */
static void test_seam_welded(void)
{
    const char *text = "# square\n"
                       "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 0\n"
                       "vt 0.1 0.1\nvt 0.4 0.1\nvt 0.1 0.4\nvt 0.6 0.1\nvt 0.9 0.1\nvt 0.9 0.4\nvt 0.6 0.4\n"
                       "f 5/1 3/2 4/3\n"
                       "f 1/4 2/5 3/6\n";
    fs_mesh m;
    double *uv;
    CHECK(parse(text, &m, &uv) == 0);
    CHECK(m.domain.type == FS_DOMAIN_MESH);
    CHECK(m.n_nodes == 4); /* v 5 is v 1 */
    CHECK(m.n_tris == 2);
    CHECK(m.n_edges == 5);
    int shared = 0;
    for (int32_t e = 0; e < m.n_edges; e++)
        shared += m.edge_tri[2 * e + 1] >= 0;
    CHECK(shared == 1);
    CHECK(m.adj[0] == 1 || m.adj[1] == 1 || m.adj[2] == 1);
    /* area 4 cm^2 over texture area 2 * 0.045: 6.67 cm per unit */
    CHECK_NEAR(m.domain.width, sqrt(4.0 / 0.09), 1e-9);
    CHECK_NEAR(uv[6 + 2], 0.9, 0.0);
    fs_mesh_free(&m);
    free(uv);
}

/* Quads become two triangles; v/vt/vn and negative indices are read. */
static void test_polygons_and_indices(void)
{
    const char *text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                       "f -4/-4/1 -3/-3/1 -2/-2/1 -1/-1/1\n";
    fs_mesh m;
    double *uv;
    CHECK(parse(text, &m, &uv) == 0);
    CHECK(m.n_tris == 2 && m.n_nodes == 4);
    CHECK_NEAR(m.domain.width, 1.0, 1e-12);
    fs_mesh_free(&m);
    free(uv);
}

static void expect_refusal(const char *text, const char *needle)
{
    fs_mesh m;
    double *uv;
    fs_error_clear();
    int rc = parse(text, &m, &uv);
    CHECK_MSG(rc == -1 && fs_error_domain() == FS_ERR_DATA, "accepted or wrong status for '%s'", needle);
    CHECK_MSG(strstr(fs_error_message(), "t.obj") && strstr(fs_error_message(), needle), "message '%s' lacks '%s'",
              fs_error_message(), needle);
    if (rc == 0) {
        fs_mesh_free(&m);
        free(uv);
    }
}

static void test_refusals(void)
{
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "needs UVs");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1\n", "at least 3 corners");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 4/3\n", "vertex defined above");
    expect_refusal("v 0 0 x\n", "three numbers");
    expect_refusal("v 0 0 0\nvt 0 0\n", "no faces");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1.5\nf 1/1 2/2 3/3\n", "outside [0, 1]");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 0.5 0.5\nvt 1 1\nf 1/1 2/2 3/3\n",
                   "degenerate texture coordinates");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 2 0 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n", "degenerate triangle");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 1/3\n", "degenerate triangle");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n"
                   "vt 0 0\nvt 0.3 0\nvt 0 0.3\nvt 0.6 0.6\nvt 0.9 0.9\nvt 0.6 0.9\nvt 0.9 0.6\n"
                   "f 1/1 2/2 3/3\nf 2/4 1/5 4/6\nf 1/4 2/7 5/6\n",
                   "non-manifold edge");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 0.5 0\nvt 0 0.5\nvt 0.5 0.5\n"
                   "f 1/1 2/2 3/3\nf 2/2 3/3 4/4\n",
                   "not consistently oriented");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\n"
                   "vt 0.1 0.1\nvt 0.3 0.1\nvt 0.1 0.3\nvt 0.6 0.6\nvt 0.8 0.6\nvt 0.6 0.8\n"
                   "f 1/1 2/2 3/3\nf 1/4 4/5 5/6\n",
                   "non-manifold vertex");
    expect_refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
                   "f 1/1 2/2 3/3\nf 2/2 4/4 3/1\n",
                   "overlap");
    /* over the size limit: fans of 64-corner faces */
    size_t cap = 1 << 22, len = 0;
    char *big = malloc(cap);
    len += (size_t)snprintf(big + len, cap - len, "v 0 0 0\nvt 0 0\n");
    while (len < cap - 400) {
        len += (size_t)snprintf(big + len, cap - len, "f");
        for (int k = 0; k < 64; k++)
            len += (size_t)snprintf(big + len, cap - len, " 1/1");
        len += (size_t)snprintf(big + len, cap - len, "\n");
    }
    expect_refusal(big, "more than 200000 triangles");
    free(big);
}

int main(void)
{
    RUN(test_seam_welded);
    RUN(test_polygons_and_indices);
    RUN(test_refusals);
    return check_finish();
}
