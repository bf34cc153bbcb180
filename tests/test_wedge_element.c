/* Tests of the 6-node wedge element: shape functions, quadrature, rigid modes, patch test, eigenstrain. */
#include <math.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "check.h"
#include "dense.h"
#include "model/wedge/element.h"

/* A general wedge: non-right bottom triangle off the z = 0 plane, each top node shifted differently
 * (sheared, tapered, twisted). Node i + 3 is above node i. Lengths in cm. */
static const double general[18] = {
    0.0, 0.0, 0.0,   2.0, 0.3, 0.1,   0.4, 1.7, -0.2,
    0.3, 0.2, 0.9,   2.1, 0.7, 1.2,   0.75, 1.6, 0.6,
};

/* Natural coordinates of the nodes (thesis Fig. 5.6). */
static const double node_rsz[6][3] = {{1, 0, -1}, {0, 1, -1}, {0, 0, -1}, {1, 0, 1}, {0, 1, 1}, {0, 0, 1}};

static double max_abs(const double *a, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(a[i]));
    return m;
}

/* Solves the n x n system m y = b (n <= 18) by Gaussian elimination with partial pivoting. */
static void solve_dense(double *m, double *b, int n)
{
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(m[n * r + c]) > fabs(m[n * piv + c]))
                piv = r;
        for (int k = 0; k < n; k++) {
            double t = m[n * c + k];
            m[n * c + k] = m[n * piv + k];
            m[n * piv + k] = t;
        }
        double t = b[c];
        b[c] = b[piv];
        b[piv] = t;
        for (int r = c + 1; r < n; r++) {
            double f = m[n * r + c] / m[n * c + c];
            for (int k = c; k < n; k++)
                m[n * r + k] -= f * m[n * c + k];
            b[r] -= f * b[c];
        }
    }
    for (int r = n - 1; r >= 0; r--) {
        double sum = b[r];
        for (int k = r + 1; k < n; k++)
            sum -= m[n * r + k] * b[k];
        b[r] = sum / m[n * r + r];
    }
}

static void mat_vec18(const double K[324], const double u[18], double out[18])
{
    for (int i = 0; i < 18; i++) {
        double sum = 0.0;
        for (int j = 0; j < 18; j++)
            sum += K[18 * i + j] * u[j];
        out[i] = sum;
    }
}

/* Nodal displacements of the linear field u(x) = a + G x (G row-major, G[3i+j] = du_i/dx_j). */
static void linear_field(const double x[18], const double a[3], const double G[9], double u[18])
{
    for (int n = 0; n < 6; n++)
        for (int i = 0; i < 3; i++)
            u[3 * n + i] = a[i] + G[3 * i] * x[3 * n] + G[3 * i + 1] * x[3 * n + 1] + G[3 * i + 2] * x[3 * n + 2];
}

/* The Voigt strain (engineering shears) of displacement gradient G. */
static void voigt_of_gradient(const double G[9], double e[6])
{
    e[0] = G[0];
    e[1] = G[4];
    e[2] = G[8];
    e[3] = G[1] + G[3];
    e[4] = G[5] + G[7];
    e[5] = G[6] + G[2];
}

static void test_shape_functions(void)
{
    /* Kronecker delta at the nodes (thesis Eq. 5.7, 5.8). */
    for (int j = 0; j < 6; j++) {
        double n[6];
        fs_wedge_shape(node_rsz[j][0], node_rsz[j][1], node_rsz[j][2], n);
        for (int i = 0; i < 6; i++)
            CHECK(n[i] == (i == j ? 1.0 : 0.0));
    }
    /* Partition of unity, and the derivatives match central differences (shape functions are at most
     * bilinear, so the difference quotient is exact up to rounding). */
    for (uint64_t k = 0; k < 50; k++) {
        double r = fs_rand01(3, FS_RNG_TEST, 3 * k), s = (1 - r) * fs_rand01(3, FS_RNG_TEST, 3 * k + 1);
        double z = fs_rand_range(3, FS_RNG_TEST, 3 * k + 2, -1, 1);
        double n[6], dn[18], sum = 0;
        fs_wedge_shape(r, s, z, n);
        fs_wedge_shape_deriv(r, s, z, dn);
        for (int i = 0; i < 6; i++) {
            sum += n[i];
            CHECK(n[i] >= 0.0 && n[i] <= 1.0);
        }
        CHECK_NEAR(sum, 1.0, 1e-15);
        const double h = 1e-4;
        for (int c = 0; c < 3; c++) {
            double p[3] = {r, s, z}, m[3] = {r, s, z}, np[6], nm[6];
            p[c] += h;
            m[c] -= h;
            fs_wedge_shape(p[0], p[1], p[2], np);
            fs_wedge_shape(m[0], m[1], m[2], nm);
            for (int i = 0; i < 6; i++)
                CHECK_NEAR(dn[3 * i + c], (np[i] - nm[i]) / (2 * h), 1e-11);
        }
    }
}

static void test_gauss_rule(void)
{
    /* Thesis Table 5.1: (2/3, 1/6), (1/6, 2/3), (1/6, 1/6) at zeta = +-0.77459666924 and 0; weights in
     * the ratio 5 : 8 : 5 through the thickness, summing to the reference volume 1. */
    double sum = 0.0;
    for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
        const double *p = fs_wedge_gauss[g];
        CHECK_NEAR(fabs(p[2]), g / 3 == 1 ? 0.0 : 0.77459666924, 1e-11);
        CHECK(g / 3 != 0 || p[2] > 0); /* the first three are nearest the top face */
        CHECK_NEAR(p[3], g / 3 == 1 ? 8.0 / 54.0 : 5.0 / 54.0, 1e-16);
        CHECK_NEAR(p[0] + p[1], g % 3 == 2 ? 1.0 / 3.0 : 5.0 / 6.0, 1e-15);
        sum += p[3];
    }
    CHECK_NEAR(sum, 1.0, 1e-15);
    /* Exact for r^2 zeta^4 (degree 2 on the triangle, degree 5 through the thickness): the integral of
     * r^2 over the reference triangle is 1/12, of zeta^4 over [-1, 1] is 2/5. */
    double q = 0.0;
    for (int g = 0; g < FS_WEDGE_GAUSS; g++)
        q += fs_wedge_gauss[g][3] * fs_wedge_gauss[g][0] * fs_wedge_gauss[g][0] * pow(fs_wedge_gauss[g][2], 4);
    CHECK_NEAR(q, 1.0 / 30.0, 1e-15);
}

static void test_volume(void)
{
    /* A sheared prism: top = bottom + offset. Volume = base area * height, whatever the shear. */
    const double base[9] = {0.1, 0.2, 0.0, 1.3, 0.4, 0.0, 0.5, 1.1, 0.0};
    const double off[3] = {0.7, -0.4, 0.35};
    double x[18], vol;
    for (int n = 0; n < 3; n++)
        for (int c = 0; c < 3; c++) {
            x[3 * n + c] = base[3 * n + c];
            x[3 * (n + 3) + c] = base[3 * n + c] + off[c];
        }
    double area = 0.5 * ((base[3] - base[0]) * (base[7] - base[1]) - (base[4] - base[1]) * (base[6] - base[0]));
    CHECK(fs_wedge_volume(x, &vol) == 0);
    CHECK_NEAR(vol, area * off[2], 1e-15);

    /* A frustum: the top triangle is the bottom scaled by 0.4 towards an apex above. Its side faces are
     * planar and the volume is h/3 (A1 + A2 + sqrt(A1 A2)). */
    const double apex[3] = {0.6, 0.5, 2.0}, lambda = 0.4;
    for (int n = 0; n < 3; n++)
        for (int c = 0; c < 3; c++)
            x[3 * (n + 3) + c] = apex[c] + lambda * (base[3 * n + c] - apex[c]);
    double a2 = lambda * lambda * area, h = (1 - lambda) * apex[2];
    CHECK(fs_wedge_volume(x, &vol) == 0);
    CHECK_NEAR(vol, h / 3 * (area + a2 + sqrt(area * a2)), 1e-14);

    /* Translating and rotating the element keeps its volume; scaling by k multiplies it by k^3. */
    double v0, v1, v2, moved[18], scaled[18];
    CHECK(fs_wedge_volume(general, &v0) == 0);
    const double c = cos(0.7), s = sin(0.7);
    for (int n = 0; n < 6; n++) {
        const double *p = general + 3 * n;
        moved[3 * n] = c * p[0] - s * p[1] + 5.0;
        moved[3 * n + 1] = s * p[0] + c * p[1] - 3.0;
        moved[3 * n + 2] = p[2] + 1.0;
        for (int k = 0; k < 3; k++)
            scaled[3 * n + k] = 0.1 * p[k];
    }
    CHECK(fs_wedge_volume(moved, &v1) == 0);
    CHECK(fs_wedge_volume(scaled, &v2) == 0);
    CHECK(v0 > 0);
    CHECK_NEAR(v1, v0, 1e-14);
    CHECK_NEAR(v2, 1e-3 * v0, 1e-17);
}

static void test_stiffness_symmetric_and_rigid(void)
{
    double D[36], K[324], Kc[324], ev[18];
    CHECK(fs_wedge_elasticity(1000.0, 0.3, D) == 0);
    CHECK(fs_wedge_stiffness(general, D, K) == 0);
    double kmax = max_abs(K, 324), asym = 0.0;
    for (int i = 0; i < 18; i++)
        for (int j = 0; j < 18; j++)
            asym = fmax(asym, fabs(K[18 * i + j] - K[18 * j + i]));
    CHECK(asym <= 1e-12 * kmax);
    for (int i = 0; i < 18; i++)
        CHECK(K[18 * i + i] > 0.0);

    /* Exactly six zero eigenvalues (three translations, three rotations); the rest positive. */
    memcpy(Kc, K, sizeof Kc);
    jacobi_eigenvalues(Kc, 18, ev);
    double emax = ev[17];
    for (int i = 0; i < 6; i++)
        CHECK_MSG(fabs(ev[i]) < 1e-10 * emax, "eigenvalue %d = %g of %g", i, ev[i], emax);
    CHECK_MSG(ev[6] > 1e-3 * emax, "seventh eigenvalue %g of %g", ev[6], emax);

    /* K annihilates each rigid mode: u = e_k (translation) and u = e_k x x (rotation). */
    for (int k = 0; k < 6; k++) {
        double u[18], f[18];
        for (int n = 0; n < 6; n++) {
            const double *p = general + 3 * n;
            double w[3] = {0, 0, 0};
            if (k < 3) {
                u[3 * n] = k == 0, u[3 * n + 1] = k == 1, u[3 * n + 2] = k == 2;
                continue;
            }
            w[k - 3] = 1.0;
            u[3 * n] = w[1] * p[2] - w[2] * p[1];
            u[3 * n + 1] = w[2] * p[0] - w[0] * p[2];
            u[3 * n + 2] = w[0] * p[1] - w[1] * p[0];
        }
        mat_vec18(K, u, f);
        CHECK_MSG(max_abs(f, 18) <= 1e-12 * kmax * max_abs(u, 18), "mode %d: |K u| = %g", k, max_abs(f, 18));
    }
}

/* The stiffness is the dense quadrature sum of B' D B det J w bit for bit (the element multiplies only
 * B's nonzero entries, whose other terms are exact zeros), also for a D with no zero entry, which
 * uses every entry the element reads. B is written out here from its definition (thesis §5.3.3). */
static void test_stiffness_dense_sum(void)
{
    double D[36], K[324], ref[18][18] = {{0}};
    for (int a = 0; a < 6; a++)
        for (int b = a; b < 6; b++)
            D[6 * a + b] = D[6 * b + a] = a == b ? 10.0 + a : 1.0 / (2.0 + a + 3.0 * b);
    CHECK(fs_wedge_stiffness(general, D, K) == 0);
    for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
        const double *p = fs_wedge_gauss[g];
        double dndx[18], detj, B[6][18] = {{0}}, DB[6][18];
        CHECK(fs_wedge_gradients(general, p[0], p[1], p[2], dndx, &detj) == 0);
        for (int n = 0; n < 6; n++) {
            double dx = dndx[3 * n], dy = dndx[3 * n + 1], dz = dndx[3 * n + 2];
            B[0][3 * n] = dx, B[1][3 * n + 1] = dy, B[2][3 * n + 2] = dz;
            B[3][3 * n] = dy, B[3][3 * n + 1] = dx;
            B[4][3 * n + 1] = dz, B[4][3 * n + 2] = dy;
            B[5][3 * n] = dz, B[5][3 * n + 2] = dx;
        }
        for (int a = 0; a < 6; a++)
            for (int j = 0; j < 18; j++) {
                double sum = 0.0;
                for (int b = 0; b < 6; b++)
                    sum += D[6 * a + b] * B[b][j];
                DB[a][j] = sum;
            }
        for (int i = 0; i < 18; i++)
            for (int j = i; j < 18; j++) {
                double sum = 0.0;
                for (int a = 0; a < 6; a++)
                    sum += B[a][i] * DB[a][j];
                ref[i][j] += sum * (detj * p[3]);
            }
    }
    int differ = 0;
    for (int i = 0; i < 18; i++)
        for (int j = i; j < 18; j++)
            differ += K[18 * i + j] != ref[i][j] || K[18 * j + i] != ref[i][j];
    CHECK_MSG(differ == 0, "%d entries differ from the dense sum", differ);
}

static void test_stiffness_scales_with_e(void)
{
    double D1[36], D2[36], K1[324], K2[324];
    CHECK(fs_wedge_elasticity(1.0, 0.25, D1) == 0);
    CHECK(fs_wedge_elasticity(3.7, 0.25, D2) == 0);
    CHECK(fs_wedge_stiffness(general, D1, K1) == 0);
    CHECK(fs_wedge_stiffness(general, D2, K2) == 0);
    double kmax = max_abs(K2, 324), worst = 0.0;
    for (int i = 0; i < 324; i++)
        worst = fmax(worst, fabs(K2[i] - 3.7 * K1[i]));
    CHECK(worst <= 1e-13 * kmax);
    /* Stiffness scales like length: the same wedge 10x smaller is 10x softer (K ~ E L). */
    double small[18], Ks[324];
    for (int i = 0; i < 18; i++)
        small[i] = 0.1 * general[i];
    CHECK(fs_wedge_stiffness(small, D1, Ks) == 0);
    worst = 0.0;
    for (int i = 0; i < 324; i++)
        worst = fmax(worst, fabs(Ks[i] - 0.1 * K1[i]));
    CHECK(worst <= 1e-13 * max_abs(K1, 324));
    /* The material matrix itself: lambda + 2 mu on the diagonal, lambda off it, mu for shears. */
    double E = 3.7, nu = 0.25, lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    CHECK_NEAR(D2[0], lam + 2 * mu, 1e-14);
    CHECK_NEAR(D2[1], lam, 1e-14);
    CHECK_NEAR(D2[6 * 3 + 3], mu, 1e-14);
    CHECK(D2[3] == 0.0 && D2[6 * 4 + 5] == 0.0);
}

static void test_patch(void)
{
    /* Any linear displacement a + G x gives the constant strain sym(G) everywhere, exactly. */
    double D[36];
    CHECK(fs_wedge_elasticity(500.0, 0.2, D) == 0);
    for (uint64_t trial = 0; trial < 20; trial++) {
        double a[3], G[9], u[18], want[6];
        for (int i = 0; i < 3; i++)
            a[i] = fs_rand_range(5, FS_RNG_TEST, 12 * trial + (uint64_t)i, -1, 1);
        for (int i = 0; i < 9; i++)
            G[i] = fs_rand_range(5, FS_RNG_TEST, 12 * trial + 3 + (uint64_t)i, -0.01, 0.01);
        linear_field(general, a, G, u);
        voigt_of_gradient(G, want);
        double scale = max_abs(want, 6);
        for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
            double e[6];
            const double *p = fs_wedge_gauss[g];
            CHECK(fs_wedge_strain(general, u, p[0], p[1], p[2], e) == 0);
            for (int c = 0; c < 6; c++)
                CHECK_NEAR(e[c], want[c], 1e-12 * scale);
        }
        /* The element stress is then D sym(G) at every Gauss point and at the centre. */
        double sg[54], sc[6], sw[6];
        for (int i = 0; i < 6; i++) {
            sw[i] = 0.0;
            for (int j = 0; j < 6; j++)
                sw[i] += D[6 * i + j] * want[j];
        }
        CHECK(fs_wedge_stress(general, D, u, NULL, sg, sc) == 0);
        for (int c = 0; c < 6; c++) {
            CHECK_NEAR(sc[c], sw[c], 1e-12 * max_abs(sw, 6));
            for (int g = 0; g < FS_WEDGE_GAUSS; g++)
                CHECK_NEAR(sg[6 * g + c], sw[c], 1e-12 * max_abs(sw, 6));
        }
    }
}

static void test_eigenstrain(void)
{
    double D[36], K[324], G[9], a[3] = {0.2, -0.1, 0.05}, u[18], eps0[6], f[18], Ku[18];
    CHECK(fs_wedge_elasticity(800.0, 0.35, D) == 0);
    CHECK(fs_wedge_stiffness(general, D, K) == 0);
    for (int i = 0; i < 9; i++)
        G[i] = fs_rand_range(9, FS_RNG_TEST, (uint64_t)i, -0.02, 0.02);
    linear_field(general, a, G, u);
    voigt_of_gradient(G, eps0);

    /* An eigenstrain equal to the applied strain leaves no stress. */
    double sg[54], sc[6];
    CHECK(fs_wedge_stress(general, D, u, eps0, sg, sc) == 0);
    double smax = 800.0 * max_abs(eps0, 6);
    CHECK(max_abs(sg, 54) <= 1e-12 * smax);
    CHECK(max_abs(sc, 6) <= 1e-12 * smax);
    /* Only one output is fine. */
    CHECK(fs_wedge_stress(general, D, u, eps0, NULL, sc) == 0);
    CHECK(fs_wedge_stress(general, D, u, eps0, sg, NULL) == 0);

    /* The equivalent force is what that free displacement needs: K u = f. */
    CHECK(fs_wedge_eigenstrain_force(general, D, eps0, f) == 0);
    mat_vec18(K, u, Ku);
    double fmax_ = max_abs(f, 18);
    CHECK(fmax_ > 0.0);
    for (int i = 0; i < 18; i++)
        CHECK_NEAR(Ku[i], f[i], 1e-12 * fmax_);

    /* Self-equilibrated: zero net force and zero net moment about the origin. */
    double force[3] = {0, 0, 0}, moment[3] = {0, 0, 0};
    for (int n = 0; n < 6; n++) {
        const double *p = general + 3 * n, *fn = f + 3 * n;
        for (int c = 0; c < 3; c++)
            force[c] += fn[c];
        moment[0] += p[1] * fn[2] - p[2] * fn[1];
        moment[1] += p[2] * fn[0] - p[0] * fn[2];
        moment[2] += p[0] * fn[1] - p[1] * fn[0];
    }
    double xmax = max_abs(general, 18);
    for (int c = 0; c < 3; c++) {
        CHECK_NEAR(force[c], 0.0, 1e-13 * fmax_);
        CHECK_NEAR(moment[c], 0.0, 1e-13 * fmax_ * xmax);
    }
    /* Isotropic shrinkage pulls the nodes inwards: the force points towards the centroid. */
    const double shrink[6] = {-0.01, -0.01, -0.01, 0, 0, 0};
    double centroid[3] = {0, 0, 0};
    for (int n = 0; n < 6; n++)
        for (int c = 0; c < 3; c++)
            centroid[c] += general[3 * n + c] / 6.0;
    CHECK(fs_wedge_eigenstrain_force(general, D, shrink, f) == 0);
    for (int n = 0; n < 6; n++) {
        double dot = 0.0;
        for (int c = 0; c < 3; c++)
            dot += f[3 * n + c] * (general[3 * n + c] - centroid[c]);
        CHECK(dot < 0.0);
    }
}

static void test_bonded_layer(void)
{
    /* Spec §9: a layer bonded to its background (no in-plane displacement) under isotropic shrinkage s
     * carries the in-plane stress E s / (1 - nu) and no normal stress, and its free top moves by
     * -s (1 + nu) / (1 - nu) h. One sheared wedge on the z = 0 plane, x and y fixed everywhere,
     * z fixed at the bottom, the three top z displacements free. */
    const double E = 200.0, nu = 0.3, s = 0.004, h = 0.5;
    const double x[18] = {0.1, 0.2, 0, 1.3, 0.4, 0, 0.5, 1.1, 0,
                          0.4, 0.35, h, 1.6, 0.55, h, 0.8, 1.25, h};
    const double eps0[6] = {-s, -s, -s, 0, 0, 0};
    double D[36], K[324], f[18], m[9], b[3], u[18] = {0};
    CHECK(fs_wedge_elasticity(E, nu, D) == 0);
    CHECK(fs_wedge_stiffness(x, D, K) == 0);
    CHECK(fs_wedge_eigenstrain_force(x, D, eps0, f) == 0);
    const int free_dof[3] = {3 * 3 + 2, 3 * 4 + 2, 3 * 5 + 2};
    for (int i = 0; i < 3; i++) {
        b[i] = f[free_dof[i]];
        for (int j = 0; j < 3; j++)
            m[3 * i + j] = K[18 * free_dof[i] + free_dof[j]];
    }
    solve_dense(m, b, 3);
    for (int i = 0; i < 3; i++) {
        u[free_dof[i]] = b[i];
        CHECK_NEAR(b[i], -s * (1 + nu) / (1 - nu) * h, 1e-14);
    }
    double sg[54];
    CHECK(fs_wedge_stress(x, D, u, eps0, sg, NULL) == 0);
    double want = E * s / (1 - nu);
    for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
        CHECK_NEAR(sg[6 * g], want, 1e-12 * want);
        CHECK_NEAR(sg[6 * g + 1], want, 1e-12 * want);
        for (int c = 2; c < 6; c++)
            CHECK_NEAR(sg[6 * g + c], 0.0, 1e-12 * want);
    }
}

static void test_errors(void)
{
    double D[36], K[324], vol, f[18];
    fs_error_clear();
    CHECK(fs_wedge_elasticity(0.0, 0.3, D) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK(fs_wedge_elasticity(10.0, 0.5, D) == -1);
    CHECK(fs_wedge_elasticity(10.0, -1.0, D) == -1);
    CHECK(fs_wedge_elasticity(NAN, 0.2, D) == -1);
    fs_error_clear();
    /* Top and bottom swapped: the element is inside out. */
    double inverted[18];
    memcpy(inverted, general + 9, 9 * sizeof(double));
    memcpy(inverted + 9, general, 9 * sizeof(double));
    CHECK(fs_wedge_elasticity(10.0, 0.2, D) == 0);
    CHECK(fs_wedge_stiffness(inverted, D, K) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    fs_error_clear();
    CHECK(fs_wedge_volume(inverted, &vol) == -1);
    CHECK(fs_wedge_eigenstrain_force(inverted, D, (const double[6]){0.1, 0, 0, 0, 0, 0}, f) == -1);
    /* A flat element (zero thickness) is degenerate. */
    double flat[18];
    memcpy(flat, general, 9 * sizeof(double));
    memcpy(flat + 9, general, 9 * sizeof(double));
    CHECK(fs_wedge_volume(flat, &vol) == -1);
    fs_error_clear();
}

int main(void)
{
    RUN(test_shape_functions);
    RUN(test_gauss_rule);
    RUN(test_volume);
    RUN(test_stiffness_symmetric_and_rigid);
    RUN(test_stiffness_dense_sum);
    RUN(test_stiffness_scales_with_e);
    RUN(test_patch);
    RUN(test_eigenstrain);
    RUN(test_bonded_layer);
    RUN(test_errors);
    return check_finish();
}
