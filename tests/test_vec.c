/* Tests of the small vector and 3x3 matrix helpers: the adjugate and inverse against hand-computed
 * cases, m inv = I, the leading minors of a symmetric positive definite matrix. */
#include <string.h>

#include "base/rng.h"
#include "base/vec.h"
#include "check.h"

/* An integer matrix: its adjugate and determinant are exact. */
static void test_mat3_adjugate_exact(void)
{
    const double m[9] = {2, -1, 0, -1, 2, -1, 0, -1, 2}; /* the 1-D Laplacian: det 4 */
    double adj[9];
    CHECK(fs_mat3_adjugate(m, adj) == 4.0);
    const double want[9] = {3, 2, 1, 2, 4, 2, 1, 2, 3};
    CHECK(memcmp(adj, want, sizeof want) == 0);
    CHECK(adj[8] == 3.0); /* the leading 2x2 minor */
    double inv[9];
    CHECK(fs_mat3_inverse(m, inv) == 4.0);
    CHECK(inv[0] == 0.75 && inv[1] == 0.5 && inv[4] == 1.0 && inv[8] == 0.75);
    /* in place */
    double a[9];
    memcpy(a, m, sizeof a);
    fs_mat3_inverse(a, a);
    CHECK(memcmp(a, inv, sizeof a) == 0);
    /* a non-symmetric matrix: adj is the transposed cofactor matrix */
    const double n[9] = {1, 2, 3, 0, 1, 4, 5, 6, 0}; /* det 1 */
    CHECK(fs_mat3_adjugate(n, adj) == 1.0);
    const double want_n[9] = {-24, 18, 5, 20, -15, -4, -5, 4, 1};
    CHECK(memcmp(adj, want_n, sizeof want_n) == 0);
    /* singular: det 0 */
    const double s[9] = {1, 2, 3, 2, 4, 6, 0, 1, 1};
    CHECK(fs_mat3_adjugate(s, adj) == 0.0);
}

/* Random symmetric positive definite matrices: m inv is the identity to rounding. */
static void test_mat3_inverse_random(void)
{
    double worst = 0.0;
    for (int trial = 0; trial < 200; trial++) {
        double b[9], m[9], inv[9];
        for (int k = 0; k < 9; k++)
            b[k] = fs_rand01(7, FS_RNG_TEST, 9 * (uint64_t)trial + (uint64_t)k) - 0.5;
        for (int i = 0; i < 3; i++) /* m = b b^T + 0.1 I */
            for (int j = 0; j < 3; j++)
                m[3 * i + j] = b[3 * i] * b[3 * j] + b[3 * i + 1] * b[3 * j + 1] + b[3 * i + 2] * b[3 * j + 2] +
                               (i == j ? 0.1 : 0.0);
        double adj[9], det = fs_mat3_adjugate(m, adj);
        CHECK(m[0] > 0.0 && adj[8] > 0.0 && det > 0.0);
        CHECK(fs_mat3_inverse(m, inv) == det);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double p = m[3 * i] * inv[j] + m[3 * i + 1] * inv[3 + j] + m[3 * i + 2] * inv[6 + j];
                double e = fabs(p - (i == j));
                worst = e > worst ? e : worst;
            }
    }
    CHECK(worst < 1e-12);
}

int main(void)
{
    RUN(test_mat3_adjugate_exact);
    RUN(test_mat3_inverse_random);
    return check_finish();
}
