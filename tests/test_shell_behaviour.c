/* Tests of the shell model against plate and beam theory: a simply supported plate, a cantilever, a free bilayer, plasticity. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "check.h"
#include "shell_fixture.h"

/* A flat n x n plate, a = 1 cm, h = 0.01 cm, simply supported (w = 0 along the border, in-plane rigid
 * motion held at two corners), under a uniform load q: the centre deflection over q a^4 / D. */
static double plate_centre_deflection(int n)
{
    fs_mesh m;
    shell_test_grid(&m, n, n, 1.0, 1.0, 0.0, 0.0, 1, true);
    fs_model_setup c = shell_test_setup();
    c.material.thickness = 0.01;
    fs_shell *s = fs_shell_build(&m, &c);
    FS_ASSERT(s);
    double E = c.material.young, nu = c.material.poisson, h = c.material.thickness;
    double D = E * h * h * h / (12.0 * (1.0 - nu * nu));
    double q = 1e-4 * h * D / 0.00406; /* a centre deflection of about h / 10000: linear */
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            int32_t v = j * (n + 1) + i;
            if (i == 0 || j == 0 || i == n || j == n)
                shell_test_pin(s, v, 4);
            s->f_ext[3 * v + 2] = q * s->node_area[v];
        }
    shell_test_pin(s, 0, 3);
    shell_test_pin(s, n, 2);
    fs_shell_number_dofs(s);
    int rc = fs_shell_equilibrium(s);
    CHECK(rc == 0);
    int32_t centre = (n / 2) * (n + 1) + n / 2;
    double w = s->x[3 * centre + 2] - s->rest[3 * centre + 2];
    fs_shell_destroy(s);
    fs_mesh_free(&m);
    return w / (q / D);
}

static void test_simply_supported_plate(void)
{
    const double exact = 0.00406235; /* Timoshenko & Woinowsky-Krieger, Table 8, nu = 0.3 */
    double prev = INFINITY;
    int sizes[3] = {8, 16, 32};
    for (int k = 0; k < 3; k++) {
        double w = plate_centre_deflection(sizes[k]);
        double err = fabs(w / exact - 1.0);
        printf("  plate %2d x %2d: w = %.6f q a^4 / D, error %.2f %%\n", sizes[k], sizes[k], w, 100.0 * err);
        CHECK_MSG(err < prev, "the error does not fall with refinement (%g after %g)", err, prev);
        prev = err;
    }
    CHECK_MSG(prev < 0.05, "error %.3g on the finest mesh", prev);
}

/* A cantilever strip, L = 10 cm, b = 1 cm, h = 0.1 cm, nu = 0.3, clamped at x = 0 by holding the two
 * columns of nodes at x = -dx/2 and +dx/2 (their slope is zero at x = 0), a load P along the free end. */
static void test_cantilever(void)
{
    const double L = 10.0, b = 1.0;
    const int nx = 64, ny = 6;
    double dx = L / (nx - 0.5);
    fs_mesh m;
    shell_test_grid(&m, nx, ny, L + 0.5 * dx, b, 0.0, 0.0, 1, true);
    for (int32_t v = 0; v < m.n_nodes; v++)
        m.pos[3 * v] -= 0.5 * dx;
    m.domain.width = L + 0.5 * dx; /* the frame is not used for a free plate; x may be negative */
    fs_model_setup c = shell_test_setup();
    fs_shell *s = fs_shell_build(&m, &c);
    FS_ASSERT(s);
    double E = c.material.young, h = c.material.thickness, I = b * h * h * h / 12.0;
    double P = 0.01 * h * 3.0 * E * I / (L * L * L); /* tip deflection h / 100 */
    for (int j = 0; j <= ny; j++) {
        shell_test_pin(s, j * (nx + 1), 7);
        shell_test_pin(s, j * (nx + 1) + 1, 7);
        int32_t tip = j * (nx + 1) + nx;
        s->f_ext[3 * tip + 2] = P / ny * (j == 0 || j == ny ? 0.5 : 1.0);
    }
    fs_shell_number_dofs(s);
    CHECK(fs_shell_equilibrium(s) == 0);
    double w = 0.0;
    for (int j = 0; j <= ny; j++)
        w += s->x[3 * (j * (nx + 1) + nx) + 2] / (ny + 1);
    double exact = P * L * L * L / (3.0 * E * I);
    printf("  cantilever: tip deflection %.6g, P L^3 / 3 E I = %.6g (%.2f %%)\n", w, exact, 100.0 * (w / exact - 1.0));
    CHECK_MSG(fabs(w / exact - 1.0) < 0.05, "tip deflection %g, expected %g", w, exact);
    fs_shell_destroy(s);
    fs_mesh_free(&m);
}

/* Curvature of the circle through points (x, z) by the algebraic least-squares fit (Kasa). */
static double circle_curvature(const double *x, const double *z, int n)
{
    /* minimise sum (x^2 + z^2 + D x + E z + F)^2 */
    double A[9] = {0}, r[3] = {0};
    for (int i = 0; i < n; i++) {
        double row[3] = {x[i], z[i], 1.0}, rhs = -(x[i] * x[i] + z[i] * z[i]);
        for (int a = 0; a < 3; a++) {
            for (int c = 0; c < 3; c++)
                A[3 * a + c] += row[a] * row[c];
            r[a] += row[a] * rhs;
        }
    }
    /* Cramer */
    double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) + A[2] * (A[3] * A[7] - A[4] * A[6]);
    double sol[3];
    for (int k = 0; k < 3; k++) {
        double M[9];
        memcpy(M, A, sizeof M);
        for (int a = 0; a < 3; a++)
            M[3 * a + k] = r[a];
        sol[k] = (M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                  M[2] * (M[3] * M[7] - M[4] * M[6])) / det;
    }
    double cx = -sol[0] / 2.0, cz = -sol[1] / 2.0;
    return 1.0 / sqrt(cx * cx + cz * cz - sol[2]);
}

/* A free strip whose top half shrinks by d_eps more than its bottom half curls to 3 d_eps / (2 h),
 * towards its top (the centre of the circle on the +z side). */
static void test_free_bilayer(void)
{
    const double L = 10.0, b = 0.5, d_eps = 0.002;
    const int nx = 60, ny = 4;
    fs_mesh m;
    shell_test_grid(&m, nx, ny, L, b, 0.3, 0.0, 4, true);
    fs_model_setup c = shell_test_setup();
    c.shrink.top.n = 2;
    c.shrink.top.t[0] = 0.0, c.shrink.top.v[0] = 0.0;
    c.shrink.top.t[1] = 1.0, c.shrink.top.v[1] = d_eps;
    fs_shell *s = fs_shell_build(&m, &c);
    FS_ASSERT(s);
    /* six constraints against rigid motion, none against the deformation */
    shell_test_pin(s, 0, 7);
    shell_test_pin(s, ny * (nx + 1), 5);
    shell_test_pin(s, 1, 4);
    fs_shell_number_dofs(s);
    fs_shell_set_time(s, 1.0);
    CHECK(fs_shell_equilibrium(s) == 0);
    int row = ny / 2;
    double x[61], z[61], zmean = 0.0;
    for (int i = 0; i <= nx; i++) {
        int32_t v = row * (nx + 1) + i;
        x[i] = s->x[3 * v];
        z[i] = s->x[3 * v + 2];
        zmean += z[i] / (nx + 1);
    }
    double k = circle_curvature(x, z, nx + 1), exact = 3.0 * d_eps / (2.0 * c.material.thickness);
    printf("  bilayer: curvature %.6g /cm, 3 d_eps / 2h = %.6g (%.2f %%)\n", k, exact, 100.0 * (k / exact - 1.0));
    CHECK_MSG(fabs(k / exact - 1.0) < 0.05, "curvature %g, expected %g", k, exact);
    /* towards the top: the middle of the strip lies below the chord of its ends */
    CHECK(z[nx / 2] < 0.5 * (z[0] + z[nx]));
    fs_shell_destroy(s);
    fs_mesh_free(&m);
}

/* A strip pulled past yield and let go keeps the permanent strain of linear kinematic hardening:
 * with eps_y = sigma_y / E, pi = (eps_max - eps_y) / (1 + 3 gamma / (2 (1 + nu))) (plastic.c's
 * model under uniaxial stress). */
static void test_plastic_permanent_strain(void)
{
    const double L = 4.0, b = 1.0, eps_max = 3e-3;
    const int nx = 8, ny = 2;
    fs_mesh m;
    shell_test_grid(&m, nx, ny, L, b, 0.0, 0.0, 1, true);
    fs_model_setup c = shell_test_setup();
    c.shell.yield = 1000.0; /* kPa: eps_y = 1e-3 */
    c.shell.hardening = 0.1;
    fs_shell *s = fs_shell_build(&m, &c);
    FS_ASSERT(s);
    for (int32_t v = 0; v < s->n_nodes; v++) {
        shell_test_pin(s, v, 4);
        int i = v % (nx + 1);
        if (i == 0 || i == nx)
            shell_test_pin(s, v, 1);
    }
    shell_test_pin(s, 0, 2);
    fs_shell_number_dofs(s);
    double nu = c.material.poisson, gamma = c.shell.hardening, E = c.material.young;
    int steps = 15;
    double stress_max = 0.0;
    for (int k = 1; k <= steps; k++) {
        double eps = eps_max * k / steps;
        for (int j = 0; j <= ny; j++) {
            int32_t v = j * (nx + 1) + nx;
            s->x[3 * v] = s->rest[3 * v] * (1.0 + eps);
        }
        CHECK(fs_shell_equilibrium(s) == 0);
        for (int round = 0; round < 200 && fs_shell_plastic_update(s, NULL) > 0; round++)
            CHECK(fs_shell_equilibrium(s) == 0);
    }
    /* the stress at the largest load: E times the elastic strain */
    double em[3], ec[3];
    fs_shell_update_phi(s, s->x, false);
    fs_shell_elastic_strains(s, s->x, 0, em, ec);
    stress_max = E * em[0];
    double eps_y = 1e-3 * c.shell.yield / E;
    double pi = (eps_max - eps_y) / (1.0 + 1.5 * gamma / (1.0 + nu));
    printf("  plasticity: stress at the largest strain %.5f MPa (expected %.5f)\n", stress_max, E * (eps_max - pi));
    CHECK_NEAR(stress_max, E * (eps_max - pi), 0.01 * E * (eps_max - pi));
    /* let go: the free end springs back */
    for (int j = 0; j <= ny; j++)
        s->pin[j * (nx + 1) + nx] &= (uint8_t)~1u;
    fs_shell_number_dofs(s);
    CHECK(fs_shell_equilibrium(s) == 0);
    CHECK(fs_shell_plastic_update(s, NULL) == 0); /* unloading is elastic */
    double u = 0.0;
    for (int j = 0; j <= ny; j++) {
        int32_t v = j * (nx + 1) + nx;
        u += (s->x[3 * v] - s->rest[3 * v]) / (ny + 1);
    }
    double permanent = u / L;
    printf("  plasticity: permanent strain %.6g, predicted %.6g\n", permanent, pi);
    CHECK_MSG(fabs(permanent / pi - 1.0) < 0.01, "permanent strain %g, expected %g", permanent, pi);
    /* and below yield nothing is permanent */
    fs_shell_destroy(s);
    fs_mesh_free(&m);
}

int main(void)
{
    RUN(test_simply_supported_plate);
    RUN(test_cantilever);
    RUN(test_free_bilayer);
    RUN(test_plastic_permanent_strain);
    return check_finish();
}
