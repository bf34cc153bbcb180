/* Tests of the discrete shell energy: the hinge angle, the gradient and Hessian against finite differences, rest and rigid motion. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "check.h"
#include "shell_fixture.h"

static double max_abs(const double *a, size_t n)
{
    double m = 0.0;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* A hinge folded by theta about the x axis: a = 0, b = (1, 0, 0), c1 = (0.3, 1, 0) in the plane z = 0,
 * c2 = (0.6, -cos theta, -sin theta) (below the plane for theta > 0: convex). */
static void folded_hinge(double theta, double x[12])
{
    double v[12] = {0, 0, 0, 1, 0, 0, 0.3, 1, 0, 0.6, -cos(theta), -sin(theta)};
    memcpy(x, v, sizeof v);
}

static void test_hinge_angle(void)
{
    for (int k = -4; k <= 4; k++) {
        double theta = 0.35 * k, x[12];
        folded_hinge(theta, x);
        double phi = fs_shell_hinge_phi(x, NULL, NULL);
        CHECK_NEAR(phi, 2.0 * tan(theta / 2.0), 1e-14);
    }
    /* invariant under a rigid motion */
    double x[12], y[12];
    folded_hinge(0.7, x);
    double c = cos(0.9), s = sin(0.9);
    for (int v = 0; v < 4; v++) {
        const double *p = x + 3 * v;
        y[3 * v] = c * p[0] - s * p[2] + 1.5;
        y[3 * v + 1] = p[1] - 2.0;
        y[3 * v + 2] = s * p[0] + c * p[2] + 0.25;
    }
    CHECK_NEAR(fs_shell_hinge_phi(y, NULL, NULL), 2.0 * tan(0.35), 1e-13);
}

/* grad and Hessian of phi against central differences of phi and grad, on random hinges. */
static void test_hinge_derivatives(void)
{
    double worst_g = 0.0, worst_h = 0.0;
    for (int trial = 0; trial < 20; trial++) {
        double x[12], g[12], h[144];
        folded_hinge(-1.2 + 0.12 * trial, x);
        for (int k = 0; k < 12; k++)
            x[k] += 0.2 * fs_rand_range(11, FS_RNG_TEST, 12 * (uint64_t)trial + k, -1.0, 1.0);
        fs_shell_hinge_phi(x, g, h);
        double gc[12], dg = 0.0; /* the closed-form gradient (no Hessian asked) is the chain rule's */
        fs_shell_hinge_phi(x, gc, NULL);
        for (int k = 0; k < 12; k++)
            dg = fmax(dg, fabs(gc[k] - g[k]));
        CHECK(dg <= 1e-12 * max_abs(g, 12));
        double step = 1e-5, gfd[12], hfd[144];
        for (int j = 0; j < 12; j++) {
            double xp[12], xm[12], gp[12], gm[12];
            memcpy(xp, x, sizeof xp);
            memcpy(xm, x, sizeof xm);
            xp[j] += step;
            xm[j] -= step;
            gfd[j] = (fs_shell_hinge_phi(xp, gp, NULL) - fs_shell_hinge_phi(xm, gm, NULL)) / (2.0 * step);
            for (int i = 0; i < 12; i++)
                hfd[i * 12 + j] = (gp[i] - gm[i]) / (2.0 * step);
        }
        double eg = 0.0, eh = 0.0;
        for (int i = 0; i < 12; i++)
            eg = fmax(eg, fabs(gfd[i] - g[i]));
        for (int i = 0; i < 144; i++)
            eh = fmax(eh, fabs(hfd[i] - h[i]));
        worst_g = fmax(worst_g, eg / max_abs(g, 12));
        worst_h = fmax(worst_h, eh / max_abs(h, 144));
        /* symmetric */
        double asym = 0.0;
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 12; j++)
                asym = fmax(asym, fabs(h[i * 12 + j] - h[j * 12 + i]));
        CHECK(asym <= 1e-12 * max_abs(h, 144));
    }
    CHECK_MSG(worst_g < 1e-8, "hinge gradient relative error %g", worst_g);
    CHECK_MSG(worst_h < 1e-7, "hinge Hessian relative error %g", worst_h);
}

/* A curved random shell with eigenstrains, plastic strains, a bond to moved anchors and loads,
 * deformed at random: everything the energy has. */
static fs_shell *random_shell(fs_mesh *m, fs_model_setup *c, uint64_t seed)
{
    shell_test_grid(m, 4, 3, 2.0, 1.5, 0.5, 0.3, seed, false);
    *c = shell_test_setup();
    c->shell.bond = 0.7;
    fs_shell *s = fs_shell_build(m, c);
    FS_ASSERT(s);
    s->em_iso = -0.01;
    s->kappa_h = 0.02;
    for (int32_t t = 0; t < s->n_tris; t++) {
        s->thick_factor[t] = 0.8 + 0.4 * fs_rand01(seed, FS_RNG_TEST, 1000 + (uint64_t)t);
        s->young[t] *= 0.5 + fs_rand01(seed, FS_RNG_TEST, 2000 + (uint64_t)t);
        for (int k = 0; k < 6; k++)
            s->plastic[6 * (size_t)t + k] = 0.01 * fs_rand_range(seed, FS_RNG_TEST, 3000 + 6 * (uint64_t)t + k, -1, 1);
    }
    for (int32_t i = 0; i < s->n_nodes; i++)
        for (int k = 0; k < 3; k++) {
            s->x[3 * i + k] += 0.05 * fs_rand_range(seed, FS_RNG_TEST, 5000 + 3 * (uint64_t)i + k, -1, 1);
            s->anchor[3 * i + k] += 0.02 * fs_rand_range(seed, FS_RNG_TEST, 7000 + 3 * (uint64_t)i + k, -1, 1);
            s->f_ext[3 * i + k] = 0.1 * fs_rand_range(seed, FS_RNG_TEST, 9000 + 3 * (uint64_t)i + k, -1, 1);
        }
    return s;
}

static void test_energy_derivatives(void)
{
    for (uint64_t seed = 1; seed <= 3; seed++) {
        fs_mesh m;
        fs_model_setup c;
        fs_shell *s = random_shell(&m, &c, seed);
        size_t n = 3 * (size_t)s->n_nodes;
        double *g = malloc(n * sizeof *g), *gp = malloc(n * sizeof *gp), *gm = malloc(n * sizeof *gm);
        double *x = malloc(n * sizeof *x), *gfd = malloc(n * sizeof *gfd);
        double *hfd = calloc(n * n, sizeof *hfd), *h = calloc(n * n, sizeof *h);
        memcpy(x, s->x, n * sizeof *x);
        double e = fs_shell_energy(s, x, g, true);
        CHECK(isfinite(e) && e > 0.0);
        /* the Hessian out of the upper CSC (no pins: DOF 3 i + k is free index 3 i + k) */
        CHECK(s->sys.n_free == (int32_t)n);
        for (int32_t j = 0; j < s->sys.K.n; j++)
            for (int32_t q = s->sys.K.col_ptr[j]; q < s->sys.K.col_ptr[j + 1]; q++) {
                int32_t i = s->sys.K.row_idx[q];
                h[(size_t)i * n + j] = h[(size_t)j * n + i] = s->sys.K.values[q];
            }
        double step = 1e-6;
        for (size_t j = 0; j < n; j++) {
            double keep = x[j];
            x[j] = keep + step;
            double ep = fs_shell_energy(s, x, gp, false);
            x[j] = keep - step;
            double em = fs_shell_energy(s, x, gm, false);
            x[j] = keep;
            gfd[j] = (ep - em) / (2.0 * step);
            for (size_t i = 0; i < n; i++)
                hfd[i * n + j] = (gp[i] - gm[i]) / (2.0 * step);
        }
        double eg = 0.0, eh = 0.0;
        for (size_t i = 0; i < n; i++)
            eg = fmax(eg, fabs(gfd[i] - g[i]));
        for (size_t i = 0; i < n * n; i++)
            eh = fmax(eh, fabs(hfd[i] - h[i]));
        double rg = eg / max_abs(g, n), rh = eh / max_abs(h, n * n);
        CHECK_MSG(rg < 1e-6, "seed %d: gradient relative error %g", (int)seed, rg);
        CHECK_MSG(rh < 1e-6, "seed %d: Hessian relative error %g", (int)seed, rh);
        free(g), free(gp), free(gm), free(x), free(gfd), free(hfd), free(h);
        fs_shell_destroy(s);
        fs_mesh_free(&m);
    }
}

/* At rest the energy and the forces vanish, and they stay zero under a rigid motion of a free shell. */
static void test_rest_and_rigid_motion(void)
{
    fs_mesh m;
    shell_test_grid(&m, 5, 4, 2.0, 1.5, 0.4, 0.4, 5, false);
    fs_model_setup c = shell_test_setup();
    fs_shell *s = fs_shell_build(&m, &c);
    FS_ASSERT(s);
    size_t n = 3 * (size_t)s->n_nodes;
    double *g = malloc(n * sizeof *g), *x = malloc(n * sizeof *x);
    double scale = c.material.young * c.material.thickness * 0.4; /* force of a unit strain on an edge */
    double e = fs_shell_energy(s, s->rest, g, false);
    CHECK_NEAR(e, 0.0, 1e-14 * scale);
    CHECK(max_abs(g, n) <= 1e-12 * scale);
    /* a rotation about an oblique axis and a translation */
    double ax[3] = {0.3, -0.5, 0.81}, l = sqrt(0.09 + 0.25 + 0.81 * 0.81), th = 1.1;
    for (int k = 0; k < 3; k++)
        ax[k] /= l;
    double cs = cos(th), sn = sin(th);
    for (int32_t i = 0; i < s->n_nodes; i++) {
        const double *p = s->rest + 3 * i;
        double d = ax[0] * p[0] + ax[1] * p[1] + ax[2] * p[2];
        double cr[3] = {ax[1] * p[2] - ax[2] * p[1], ax[2] * p[0] - ax[0] * p[2], ax[0] * p[1] - ax[1] * p[0]};
        for (int k = 0; k < 3; k++)
            x[3 * i + k] = p[k] * cs + cr[k] * sn + ax[k] * d * (1.0 - cs) + (k + 1) * 0.7;
    }
    e = fs_shell_energy(s, x, g, false);
    CHECK_NEAR(e, 0.0, 1e-14 * scale);
    CHECK_MSG(max_abs(g, n) <= 1e-11 * scale, "largest force under rigid motion %g", max_abs(g, n));
    /* and a small deformation has energy and forces */
    x[3 * 7 + 2] += 1e-3;
    e = fs_shell_energy(s, x, g, false);
    CHECK(e > 0.0 && max_abs(g, n) > 1e-6 * scale);
    free(g), free(x);
    fs_shell_destroy(s);
    fs_mesh_free(&m);
}

int main(void)
{
    RUN(test_hinge_angle);
    RUN(test_hinge_derivatives);
    RUN(test_energy_derivatives);
    RUN(test_rest_and_rigid_motion);
    return check_finish();
}
